#!/usr/bin/env python3
"""study/slurm/submit.sh on a real Slurm: a sharded `rvr study` as a 3-task job array, then the
dependent merge job, on a one-node cluster this test starts itself.

In a fresh folder under /tmp: munged with a new key, a minimal slurm.conf (one node: this
machine, its host name and CPU count; proctrack/linuxproc, task/none, no accounting, no
cgroups, so it runs in a container without systemd), slurmctld and slurmd in the foreground on
free ports. Then submit.sh submits a tiny study (builtin:tessphere, 64 wide, 4 s budget a
shard) and the test waits for the merge job and checks:

- while shards are still to run, the merge job is pending on afterok on the whole array;
- every array task and the merge job completed, and the merge started after the last shard
  ended;
- each shard's study.json is there, with its own `shard` {index, count};
- the merged study.json holds exactly the union of the shards' points, each shard's points
  once (same renderer, scene, N and size, same repetitions), and the shards measured disjoint
  points;
- one machine type: the merged study is OUT/merged/study.json, no comparison.md, and its
  machine is the shards'.

Every wait is bounded (--timeout for the whole test, less than ctest's); at the end, on failure
too, every job is cancelled and every daemon stopped. If the test is killed outright, the
daemons die with it (PR_SET_PDEATHSIG) and a watchdog process it started ends what they left
running. A daemon that cannot start, or a node drained because slurmd could not run a job,
fails the test with the reason and the log; nothing is skipped. Needs root (slurmd runs jobs as
their user) and Debian's slurm-wlm and munge (`make deps`).
"""

import argparse
import ctypes
import json
import os
import pathlib
import pwd
import re
import select
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

SHARDS = 3
STUDY = ["builtin:tessphere", "--width", "64", "--budget", "4"]
TOOLS = ["munged", "munge", "unmunge", "slurmctld", "slurmd", "sbatch", "scontrol", "squeue",
         "sinfo", "scancel"]
TERMINAL = {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY",
            "BOOT_FAIL", "DEADLINE", "PREEMPTED"}


class Failure(Exception):
    pass


def find_tool(name):
    path = shutil.which(name, path=os.environ.get("PATH", "") + ":/usr/sbin:/sbin")
    if path is None:
        raise Failure(f"{name} not found: install Debian's slurm-wlm and munge "
                      "(make deps, as root)")
    return path


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("", 0))
        return s.getsockname()[1]


def die_with_parent():
    # Runs in the child before exec: SIGTERM when this test process dies, however it dies.
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


def tail(path, lines=40):
    try:
        text = pathlib.Path(path).read_text(errors="replace").splitlines()
    except OSError as e:
        return f"({path}: {e.strerror})"
    return "\n".join(text[-lines:]) or f"({path} is empty)"


class Cluster:
    """munged, slurmctld and slurmd on localhost, from a folder of their own."""

    def __init__(self, root, tools, deadline):
        self.root = root
        self.tools = tools
        self.deadline = deadline
        self.daemons = []  # (name, Popen, log)
        self.conf = root / "slurm.conf"
        self.socket = root / "munge.socket"
        self.env = {k: v for k, v in os.environ.items()
                    if not k.startswith(("SLURM_", "SBATCH_", "SALLOC_", "SRUN_"))}
        self.env["SLURM_CONF"] = str(self.conf)

    def remaining(self):
        return self.deadline - time.monotonic()

    def run(self, argv, timeout=30, check=True, cleanup=False, **kwargs):
        if not cleanup:  # the cleanup has bounds of its own, past the deadline
            timeout = max(1, min(timeout, self.remaining()))
        if "input" not in kwargs:
            kwargs["stdin"] = subprocess.DEVNULL
        try:
            r = subprocess.run(argv, env=self.env, capture_output=True, text=True,
                               timeout=timeout, **kwargs)
        except subprocess.TimeoutExpired:
            raise Failure(f"{' '.join(map(str, argv))}: no answer within {timeout:.0f} s")
        if check and r.returncode != 0:
            raise Failure(f"{' '.join(map(str, argv))} exited with {r.returncode}:\n"
                          f"{r.stdout}{r.stderr}")
        return r

    def start(self, name, argv):
        log = self.root / f"{name}.out"
        with open(log, "w") as out:
            p = subprocess.Popen(argv, env=self.env, stdin=subprocess.DEVNULL, stdout=out,
                                 stderr=subprocess.STDOUT, preexec_fn=die_with_parent)
        self.daemons.append((name, p, log))

    def check_alive(self):
        for name, p, log in self.daemons:
            if p.poll() is not None:
                raise Failure(f"{name} exited with status {p.returncode}; its output:\n"
                              f"{tail(log)}\n{self.logs_hint(name)}")

    def logs_hint(self, name):
        # munged in the foreground logs to its output, shown already.
        own = {"slurmctld": "slurmctld.log", "slurmd": "slurmd.log"}
        return f"{own[name]}:\n{tail(self.root / own[name])}" if name in own else ""

    def wait_for(self, what, probe, timeout):
        end = min(time.monotonic() + timeout, self.deadline)
        while True:
            self.check_alive()
            result = probe()
            if result:
                return result
            if time.monotonic() > end:
                raise Failure(f"timed out after {timeout:.0f} s waiting for {what}")
            time.sleep(0.5)

    def start_munge(self):
        key = self.root / "munge.key"
        fd = os.open(key, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "wb") as f:
            f.write(os.urandom(128))
        self.start("munged", [self.tools["munged"], "--foreground", f"--socket={self.socket}",
                              f"--key-file={key}", f"--log-file={self.root / 'munged.log'}",
                              f"--pid-file={self.root / 'munged.pid'}",
                              f"--seed-file={self.root / 'munged.seed'}"])

        def credential_round_trip():
            if not self.socket.exists():
                return False
            cred = self.run([self.tools["munge"], "-n", "-S", str(self.socket)], check=False)
            if cred.returncode != 0:
                return False
            back = self.run([self.tools["unmunge"], "-S", str(self.socket)], check=False,
                            input=cred.stdout)
            return back.returncode == 0

        self.wait_for("munged to encode and decode a credential", credential_round_trip, 15)

    def write_conf(self, host, cpus):
        (self.root / "state").mkdir()
        (self.root / "spool").mkdir()
        (self.root / "plugstack.conf").write_text("")  # no SPANK plugins from /etc/slurm
        r = self.root
        self.conf.write_text("\n".join([
            "ClusterName=rvrtest",
            f"SlurmctldHost={host}(127.0.0.1)",
            f"SlurmctldPort={free_port()}",
            f"SlurmdPort={free_port()}",
            "SlurmUser=root",
            "SlurmdUser=root",
            "AuthType=auth/munge",
            "CredType=cred/munge",
            f"AuthInfo=socket={self.socket}",
            f"StateSaveLocation={r / 'state'}",
            f"SlurmdSpoolDir={r / 'spool'}",
            f"SlurmctldPidFile={r / 'slurmctld.pid'}",
            f"SlurmdPidFile={r / 'slurmd.pid'}",
            f"SlurmctldLogFile={r / 'slurmctld.log'}",
            f"SlurmdLogFile={r / 'slurmd.log'}",
            f"PlugStackConfig={r / 'plugstack.conf'}",
            "SlurmctldDebug=info",
            "SlurmdDebug=info",
            # No cgroups, no systemd: processes tracked by parentage, tasks not bound.
            "ProctrackType=proctrack/linuxproc",
            "TaskPlugin=task/none",
            "JobAcctGatherType=jobacct_gather/none",
            "AccountingStorageType=accounting_storage/none",
            "JobCompType=jobcomp/none",
            "MpiDefault=none",
            "SelectType=select/cons_tres",
            "SelectTypeParameters=CR_CPU",
            # The node is what this file says, whatever slurmd finds (no drain on a mismatch).
            "SlurmdParameters=config_overrides",
            "ReturnToService=2",
            # Finished jobs stay visible to scontrol for the checks.
            "MinJobAge=600",
            "KillWait=5",
            "MailProg=/bin/true",
            f"NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN",
            "PartitionName=rvr Nodes=ALL Default=YES MaxTime=INFINITE State=UP",
            ""]))

    def start_slurm(self, host):
        self.start("slurmctld", [self.tools["slurmctld"], "-D", "-f", str(self.conf)])
        self.start("slurmd", [self.tools["slurmd"], "-D", "-f", str(self.conf), "-N", host])

        def node_idle():
            ping = self.run([self.tools["scontrol"], "ping"], check=False)
            if "is UP" not in ping.stdout:
                return False
            state = self.run([self.tools["sinfo"], "-h", "-N", "-o", "%T"], check=False)
            return state.stdout.strip() == "idle"

        self.wait_for("slurmctld to answer and the node to be idle", node_idle, 40)

    def check_node(self):
        """A job slurmd could not start drains the node, and every job then waits forever."""
        r = self.run([self.tools["sinfo"], "-h", "-N", "-o", "%T|%E"])
        state, _, reason = r.stdout.strip().partition("|")
        if any(word in state for word in ("drain", "down", "fail")):
            raise Failure(f"the node is {state} ({reason}): slurmd.log says why:\n"
                          f"{tail(self.root / 'slurmd.log', 15)}")

    def job_records(self, job_id):
        r = self.run([self.tools["scontrol"], "-o", "show", "job", str(job_id)])
        return [dict(re.findall(r"(\w+)=(\S*)", line)) for line in r.stdout.splitlines() if line]

    def stop(self):
        """Cancels every job, then stops the daemons (SIGTERM, SIGKILL after 10 s), then ends
        any process still running with this cluster's SLURM_CONF (a job's slurmstepd or rvr)."""
        names = [name for name, p, _ in self.daemons if p.poll() is None]
        if "slurmctld" in names:
            try:
                user = pwd.getpwuid(os.getuid()).pw_name
                self.run([self.tools["scancel"], "--user", user], timeout=10, check=False,
                         cleanup=True)
                end = time.monotonic() + 15
                while time.monotonic() < end:
                    q = self.run([self.tools["squeue"], "-h", "-o", "%i"], timeout=10,
                                 check=False, cleanup=True)
                    if q.returncode != 0 or not q.stdout.strip():
                        break
                    time.sleep(0.5)
            except Failure as e:
                print(f"cleanup: {e}", file=sys.stderr)
        for name, p, _ in reversed(self.daemons):
            if p.poll() is None:
                p.terminate()
        for name, p, _ in reversed(self.daemons):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                print(f"cleanup: {name} ignored SIGTERM for 10 s: killed", file=sys.stderr)
                p.kill()
                p.wait()
        kill_left_over(self.conf)


def kill_left_over(conf):
    """Kills every process whose environment names this cluster's slurm.conf: only the daemons
    and what they started (slurmstepd, a job's rvr) carry it."""
    marker = f"SLURM_CONF={conf}".encode()
    for entry in pathlib.Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            environ = (entry / "environ").read_bytes().split(b"\0")
        except OSError:
            continue
        if marker in environ:
            print(f"cleanup: process {entry.name} left running by the cluster: killed",
                  file=sys.stderr)
            try:
                os.kill(int(entry.name), signal.SIGKILL)
            except ProcessLookupError:
                pass


def sweep_after(pid, root):
    """The watchdog: once process `pid` (the test) has ended, however it ended, kills what its
    cluster left running and removes the cluster's folder. If the test is killed outright
    (SIGKILL from ctest's timeout) the daemons die with it (PR_SET_PDEATHSIG), but a job's
    slurmstepd, which belongs to no one, would wait for slurmd forever."""
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        fd = None
    if fd is not None:
        select.select([fd], [], [])  # readable once the process has ended
        os.close(fd)
    kill_left_over(root / "slurm.conf")
    shutil.rmtree(root, ignore_errors=True)


def points_by_key(study, where):
    """{(renderer, scene, scene_n, n, width, height): sorted frame times of every run} of a
    study.json."""
    points = {}
    for p in study["points"]:
        key = (p["renderer"], p["scene"], p["scene_n"], p["n"], p["width"], p["height"])
        if key in points:
            raise Failure(f"{where}: point {key} appears twice")
        points[key] = sorted(t for run in p["runs"] for t in run["seconds"])
    return points


def machine_type(study):
    m = study["machine"]
    return (m["cpu"], m["threads"], m["kernels"], study["mode"])


def check_results(out):
    shards = []
    for i in range(SHARDS):
        path = out / f"shard-{i}" / "study.json"
        if not path.is_file():
            raise Failure(f"{path} is missing (log: {tail(out / 'logs' / f'shard-{i}.out')})")
        study = json.loads(path.read_text())
        if study.get("shard") != {"index": i, "count": SHARDS}:
            raise Failure(f"{path}: shard is {study.get('shard')}, not {i}/{SHARDS}")
        shards.append(study)

    merged_dir = out / "merged"
    comparison = merged_dir / "comparison.md"
    if comparison.exists():
        raise Failure(f"{comparison} exists: the shards, all run on this machine, were not "
                      "pooled as one machine type")
    groups = sorted(p.parent.name for p in merged_dir.glob("*/study.json"))
    if groups:
        raise Failure(f"{merged_dir} holds per-machine-type studies {groups}: expected one")
    path = merged_dir / "study.json"
    if not path.is_file():
        raise Failure(f"{path} is missing (log: {tail(out / 'logs' / 'merge.out')})")
    merged = json.loads(path.read_text())
    if merged.get("shard") is not None:
        raise Failure(f"{path}: shard is {merged['shard']}, not null")

    types = {machine_type(s) for s in shards + [merged]}
    if len(types) != 1:
        raise Failure(f"the shards and the merged study name {len(types)} machine types: {types}")

    union = {}
    for i, study in enumerate(shards):
        points = points_by_key(study, f"shard-{i}")
        if not points:
            raise Failure(f"shard-{i} measured no point")
        shared = union.keys() & points.keys()
        if shared:
            raise Failure(f"shard-{i} measured {len(shared)} points another shard measured too, "
                          f"e.g. {sorted(shared)[0]}")
        union.update(points)
    pooled = points_by_key(merged, "merged")
    missing = sorted(union.keys() - pooled.keys())
    extra = sorted(pooled.keys() - union.keys())
    changed = sorted(k for k in union.keys() & pooled.keys() if union[k] != pooled[k])
    if missing or extra or changed:
        raise Failure(f"merged study.json is not the union of the shards' points: "
                      f"{len(missing)} missing (e.g. {missing[:1]}), {len(extra)} not in any "
                      f"shard (e.g. {extra[:1]}), {len(changed)} with other repetitions "
                      f"(e.g. {changed[:1]})")
    counts = [len(s["points"]) for s in shards]
    print(f"ok: merged study.json: {len(pooled)} points = shards' {' + '.join(map(str, counts))}, "
          f"one machine type ({merged['machine']['cpu']}, {merged['machine']['threads']} threads)")


def check_dependency(cluster, array_id, merge_id):
    """While a shard is still to finish (each takes seconds), the merge job must be held by an
    afterok dependency on the whole array: on one node, FIFO order alone would often run it
    last anyway."""
    merge = cluster.job_records(merge_id)[0]
    tasks = cluster.job_records(array_id)
    unfinished = [t for t in tasks if t.get("JobState") not in TERMINAL]
    if not unfinished:
        print("note: every shard ended before the dependency could be looked at")
        return
    dependency = merge.get("Dependency", "")
    if merge.get("JobState") != "PENDING" or not dependency.startswith(f"afterok:{array_id}_*"):
        raise Failure(f"with shards still to finish, merge job {merge_id} is "
                      f"{merge.get('JobState')} ({merge.get('Reason')}) with dependency "
                      f"{dependency!r}, not pending on afterok:{array_id}_*")
    print(f"merge job {merge_id}: pending on {dependency}")


def check_jobs(cluster, array_id, merge_id, timeout):
    def merge_done():
        cluster.check_node()
        record = cluster.job_records(merge_id)[0]
        return record if record.get("JobState") in TERMINAL else None

    merge = cluster.wait_for(f"merge job {merge_id} to end", merge_done, timeout)
    tasks = cluster.job_records(array_id)
    states = {t.get("ArrayTaskId"): t.get("JobState") for t in tasks}
    print(f"array job {array_id}: tasks {states}; merge job {merge_id}: {merge['JobState']}")
    if merge["JobState"] != "COMPLETED" or sorted(states) != [str(i) for i in range(SHARDS)] \
            or set(states.values()) != {"COMPLETED"}:
        raise Failure(f"expected {SHARDS} completed array tasks and a completed merge job; "
                      f"merge: {merge.get('JobState')} ({merge.get('Reason')})")
    last_end = max(t["EndTime"] for t in tasks)  # ISO times: compared as text
    if merge["StartTime"] < last_end:
        raise Failure(f"the merge job started at {merge['StartTime']}, before the last shard "
                      f"ended ({last_end})")


def show_logs(root, out):
    for name in ["munged.out", "slurmctld.log", "slurmd.log"]:
        print(f"--- {name}\n{tail(root / name, 25)}", file=sys.stderr)
    for log in sorted((out / "logs").glob("*.out")) if (out / "logs").is_dir() else []:
        print(f"--- {log}\n{tail(log, 25)}", file=sys.stderr)


def main():
    if sys.argv[1:2] == ["--sweep-after"]:
        sweep_after(int(sys.argv[2]), pathlib.Path(sys.argv[3]))
        return 0
    sys.stdout.reconfigure(line_buffering=True)  # in order with stderr in ctest's log
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rvr", required=True)
    parser.add_argument("--submit", required=True, help="study/slurm/submit.sh")
    parser.add_argument("--work-dir", required=True, type=pathlib.Path)
    parser.add_argument("--timeout", type=float, default=240,
                        help="seconds for the whole test, cleanup excluded")
    args = parser.parse_args()
    deadline = time.monotonic() + args.timeout
    started = time.monotonic()

    def stop_on_signal(signum, frame):
        raise Failure(f"stopped by signal {signum}")

    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(s, stop_on_signal)

    shutil.rmtree(args.work_dir, ignore_errors=True)
    args.work_dir.mkdir(parents=True)
    out = args.work_dir / "study"
    root = None
    cluster = None
    status = 1
    try:
        if os.geteuid() != 0:
            raise Failure("needs root: slurmd starts jobs as their user and munged's key "
                          "and socket are root's (run ctest as root, as `make test` does)")
        tools = {name: find_tool(name) for name in TOOLS}
        # munged wants every folder above its socket searchable by all, and a short path
        # (a socket's path is at most 107 bytes): a folder of its own under /tmp.
        root = pathlib.Path(tempfile.mkdtemp(prefix="rvr-slurm-", dir="/tmp"))
        root.chmod(0o755)
        # In a session of its own, so that killing the test's process group spares it.
        subprocess.Popen([sys.executable, __file__, "--sweep-after", str(os.getpid()), str(root)],
                         stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True)
        cluster = Cluster(root, tools, deadline)
        cluster.start_munge()
        host = socket.gethostname().split(".")[0]
        cluster.write_conf(host, os.cpu_count())
        cluster.start_slurm(host)
        print(f"cluster up in {time.monotonic() - started:.1f} s: node {host}, "
              f"{os.cpu_count()} CPUs, {root}")

        submitted = cluster.run([args.submit, str(SHARDS), str(out), args.rvr] + STUDY,
                                timeout=60)
        print(submitted.stderr, end="")
        ids = submitted.stdout.split()
        if len(ids) != 2 or not all(i.isdigit() for i in ids):
            raise Failure(f"submit.sh printed {submitted.stdout!r}, not 'ARRAY_ID MERGE_ID'")
        array_id, merge_id = ids
        check_dependency(cluster, array_id, merge_id)
        check_jobs(cluster, array_id, merge_id, timeout=cluster.remaining())
        check_results(out)
        status = 0
    except Failure as e:
        print(f"FAIL: {e}", file=sys.stderr)
        if root is not None:
            show_logs(root, out)
    finally:
        for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
            signal.signal(s, signal.SIG_IGN)  # the cleanup is bounded: let it finish
        if cluster is not None:
            cluster.stop()
        if root is not None:
            logs = args.work_dir / "cluster"
            shutil.copytree(root, logs, ignore=shutil.ignore_patterns("*.socket*", "*.key",
                                                                     "state", "spool"),
                            dirs_exist_ok=True)
            shutil.rmtree(root, ignore_errors=True)
    print(f"{'ok' if status == 0 else 'FAILED'} in {time.monotonic() - started:.1f} s "
          f"(logs in {args.work_dir})")
    return status


if __name__ == "__main__":
    sys.exit(main())
