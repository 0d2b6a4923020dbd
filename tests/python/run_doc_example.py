"""Runs the example of docs/python.md as written: the first ```python block, in a fresh folder,
which must leave the PNG it says it writes (every file named in a savefig call)."""
import os
import pathlib
import re
import runpy
import sys


def main(doc, work_dir):
    text = pathlib.Path(doc).read_text()
    blocks = re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)
    assert blocks, f"{doc}: no ```python block"
    code = blocks[0]
    outputs = re.findall(r"savefig\(\"([^\"]+)\"", code)
    assert outputs, f"{doc}: the example saves no figure"
    work = pathlib.Path(work_dir)
    work.mkdir(parents=True, exist_ok=True)
    for name in outputs:
        (work / name).unlink(missing_ok=True)
    script = work / "example.py"
    script.write_text(code)
    os.chdir(work)
    runpy.run_path(str(script), run_name="__main__")
    for name in outputs:
        data = (work / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{name}: not a PNG"
        print(f"{name}: {len(data)} bytes")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
