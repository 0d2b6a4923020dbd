# The README's commands: `make demo` and `make test` do everything on a fresh Debian 12 machine.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
# DEMO_PACKAGES: what building the rvr command and running it need (the libraries it links or
# opens, the GL loader generator, OSMesa and EGL). TEST_PACKAGES: what only the tests, the
# benchmarks, `make sanitize` and `make fuzz` need (GoogleTest, Google Benchmark, idiff,
# Assimp's test models (tests/test_assimp_testmodels.cpp), the
# browser tests' Chromium, the schema and chart checks' Python modules, clang for libFuzzer,
# Slurm and MUNGE for the test that runs a sharded study as a job array on a one-node cluster,
# shellcheck for the Slurm scripts)
# and the Python module with its tests (pybind11, pytest, OpenImageIO's Python reader).
# WHEEL_PACKAGES: what `make wheel` needs beside DEMO_PACKAGES: the module's build (pybind11,
# Python's headers, numpy) and its wheel, built offline and tested in a venv (python3-build,
# python3-setuptools, python3-wheel, python3-venv); part of TEST_PACKAGES (python_wheel).
DEMO_PACKAGES := cmake g++ make pkg-config libosmesa6-dev libglm-dev libopenimageio-dev \
	libpng-dev libopenexr-dev libembree-dev libtbb-dev nlohmann-json3-dev libcli11-dev \
	libfmt-dev libassimp-dev python3-glad libegl-dev libegl-mesa0 libboost-dev
WHEEL_PACKAGES := pybind11-dev python3-pybind11 python3-dev python3-numpy python3-build \
	python3-setuptools python3-wheel python3-venv
TEST_PACKAGES := libgtest-dev libbenchmark-dev openimageio-tools assimp-testmodels python3-matplotlib \
	python3-jsonschema python3-websocket chromium clang-14 libclang-rt-14-dev clang-tidy-14 iwyu \
	$(WHEEL_PACKAGES) python3-pytest python3-openimageio slurm-wlm munge shellcheck
PACKAGES := $(DEMO_PACKAGES) $(TEST_PACKAGES)

.PHONY: all deps deps-demo deps-wheel build demo test check sanitize fuzz bench study clean format \
	lint wheel

all: build

# Installs the missing packages of $(1) (as root), or says which are missing.
define install_missing
	@missing=$$(for p in $(1); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; done); \
	if [ -z "$$missing" ]; then echo "$@: all packages present"; exit 0; fi; \
	if [ "$$(id -u)" != 0 ]; then echo "$@: run as root: apt-get update && apt-get install -y $$missing"; exit 1; fi; \
	echo "$@: installing $$missing"; \
	apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing
endef

deps-demo:
	$(call install_missing,$(DEMO_PACKAGES))

deps:
	$(call install_missing,$(PACKAGES))

deps-wheel:
	$(call install_missing,$(DEMO_PACKAGES) $(WHEEL_PACKAGES))

# Everything: the CLI, the benchmarks and the tests.
build: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DRVR_BUILD_TESTS=ON -DRVR_BUILD_BENCH=ON -DRVR_BUILD_PYTHON=ON
	cmake --build $(BUILD_DIR) -j $(JOBS)

# Only the rvr command (no tests, no benchmarks), so only DEMO_PACKAGES are installed.
demo: deps-demo
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DRVR_BUILD_TESTS=OFF -DRVR_BUILD_BENCH=OFF -DRVR_BUILD_PYTHON=OFF
	cmake --build $(BUILD_DIR) -j $(JOBS) --target rvr
	$(BUILD_DIR)/bin/rvr compare builtin:cornell -o rvr-out

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# The Python module as a wheel in dist/ (docs/python.md, "Installing with pip"), for Debian's
# python3: Debian's python3-build runs setup.py offline (--no-isolation: no PyPI), which has CMake
# build the module alone (no tests, no benchmarks) in build-wheel/. Then
# `pip install dist/rvr-*.whl` into a venv made with --system-site-packages (for Debian's numpy).
wheel: deps-wheel
	RVR_BUILD_JOBS=$(JOBS) /usr/bin/python3 -m build --no-isolation --wheel --outdir dist .

# The edit loop: only the tests labelled `fast` (under 2 minutes); `make test` runs them all.
check: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -L fast

# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (any UB fails the
# test), in its own build folder: SANITIZE_OPT, assert, RVR_CHECK and RVR_DCHECK on (no NDEBUG,
# and RVR_ENABLE_DCHECK so it stays on whatever the build type). SANITIZE_OPT is -O1, the level
# AddressSanitizer's documentation suggests, without debug information: the build was most of
# CI's sanitize step, and test_conformance.cpp compiles in 26 s at -O1 -g1, 44 s at -O2 -g0 and
# 60 s at -O2 -g1; the test binaries link smaller too. A report then names functions, not lines:
# `make sanitize SANITIZE_OPT="-O1 -g1"` puts the line tables back. Leaks
# inside Mesa and Assimp are suppressed by tests/sanitize/lsan.supp (third-party code only).
# Only the CLI and the test binaries are built (not the benchmarks).
SANITIZE_DIR ?= build-asan
SANITIZE_OPT ?= -O1 -g0
SANITIZE_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
SANITIZE_TARGETS := rvr rvr_python $(patsubst tests/%.cpp,%,$(wildcard tests/test_*.cpp))
# The Python module's tests run Debian's python3, which is not built with ASan: the runtime is
# preloaded so that it comes first, as ASan requires, and libstdc++ with it, without which ASan's
# __cxa_throw interceptor finds no real __cxa_throw (python3 does not link libstdc++) and the
# first C++ exception aborts ("CHECK failed: asan_interceptors.cpp:320"). CPython does not free
# everything at exit, so they run without the leak check (the module's own leaks are
# python_memory's subject).
SANITIZE_PRELOAD := $(shell gcc -print-file-name=libasan.so):$(shell gcc -print-file-name=libstdc++.so)
# lazy_loading runs python3 with the module too (and rvr under the loader's trace).
SANITIZE_PYTHON ?= python_|lazy_loading
# Brute-force conformance (`raytrace_none_*`: every scene traced with no acceleration
# structure) is left out: under ASan it alone would take longer than the rest of the suite; the
# same tracer code runs under ASan with the BVH in every other conformance case, and the
# brute-force path in test_bvh.
# python_wheel (packaging: the wheel installed into a venv) is left out too: pip and the venv's
# python would run under the preloaded ASan runtime for no memory check of rvr's own.
# MemoryEstimate.WithinTenPercentOfASessionsMeasuredPeak compares the memory estimate with a
# session's peak resident set at 10^7 triangles: under ASan the shadow memory and quarantine
# change that peak (the comparison means nothing there) and the session takes tens of minutes;
# the study's memory code still runs under ASan in the other MemoryEstimate tests.
# Two tests repeat code the suite already runs under ASan, at more than a minute each there:
# Bvh.MatchesBruteForceOnSpheresAsMeshes (the brute-force tracer over a scene of thousands of
# triangles; the same comparison runs on the other Bvh.MatchesBruteForce* scenes) and
# StudyFit.IntervalCoverageOverSeededReplicates (the same fit 1200 times to count how often its
# intervals cover the truth, a statistical property; the fit runs in the other StudyFit tests).
SANITIZE_EXCLUDE ?= Conformance[.]AgreesWithTheOtherLoopOrder/raytrace_none_|python_wheel|MemoryEstimate[.]WithinTenPercentOfASessionsMeasuredPeak|Bvh[.]MatchesBruteForceOnSpheresAsMeshes|StudyFit[.]IntervalCoverageOverSeededReplicates
# LeakSanitizer's exit-time scan (gcc 12's libsanitizer) can crash ("Tracer caught signal 11")
# on a garbage dynamic-TLS entry of a Mesa library opened with dlopen. RVR_LINK_OSMESA=ON loads
# libOSMesa and LLVM at start-up (static TLS), which avoids it, but Mesa's EGL driver is still
# opened by libEGL, so tests that make EGL contexts run with ASan and UBSan but without the
# leak check. LSAN use_tls=0 avoids the crash too but reports TLS-held objects of OpenImageIO's
# dependencies as leaks. The same rasterizer code is leak-checked through OSMesa in every
# other raster test.
SANITIZE_EGL ?= Egl|egl
# intercept_tls_get_addr=0: at exit, libgnutls's destructor (an OpenImageIO dependency) reads its
# thread-local data through __tls_get_addr, for which gcc 12's interceptor can record a garbage
# block that the exit-time scan then reads ("Tracer caught signal 11"). Without the
# interception dynamic TLS blocks are not scanned as roots: that can only add leak reports
# (objects held only there), never hide one.
SANITIZE_ASAN := strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:intercept_tls_get_addr=0
SANITIZE_LSAN := suppressions=$(CURDIR)/tests/sanitize/lsan.supp:print_suppressions=0
SANITIZE_UBSAN := print_stacktrace=1:halt_on_error=1
sanitize: deps
	cmake -S . -B $(SANITIZE_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$(SANITIZE_OPT)" -DCMAKE_CXX_FLAGS="$(SANITIZE_FLAGS)" \
		-DCMAKE_EXE_LINKER_FLAGS="$(SANITIZE_FLAGS)" -DCMAKE_SHARED_LINKER_FLAGS="$(SANITIZE_FLAGS)" \
		-DRVR_LINK_OSMESA=ON -DRVR_TEST_TIMEOUT_SCALE=10 -DRVR_TEST_BUDGET_SCALE=4 -DRVR_ENABLE_DCHECK=ON -DRVR_PYTHON_PRELOAD=$(SANITIZE_PRELOAD)
	cmake --build $(SANITIZE_DIR) -j $(JOBS) --target $(SANITIZE_TARGETS)
	cd $(SANITIZE_DIR) && \
		ASAN_OPTIONS=detect_leaks=1:$(SANITIZE_ASAN) LSAN_OPTIONS=$(SANITIZE_LSAN) \
		UBSAN_OPTIONS=$(SANITIZE_UBSAN) \
		ctest --output-on-failure -j $(JOBS) -E '$(SANITIZE_EXCLUDE)|$(SANITIZE_EGL)|$(SANITIZE_PYTHON)'
	cd $(SANITIZE_DIR) && \
		ASAN_OPTIONS=detect_leaks=0:$(SANITIZE_ASAN) UBSAN_OPTIONS=$(SANITIZE_UBSAN) \
		ctest --output-on-failure -j $(JOBS) -R '$(SANITIZE_EGL)|$(SANITIZE_PYTHON)' -E '$(SANITIZE_EXCLUDE)'

# libFuzzer (clang 14) on the scene loader and the mesh importer path, FUZZ_SECONDS per
# harness; see tests/fuzz/run.sh and notes in tests/fuzz/README.md.
FUZZ_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_FLAGS := -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
fuzz: deps
	cmake -S . -B $(FUZZ_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
		-DRVR_BUILD_FUZZERS=ON -DRVR_BUILD_TESTS=OFF -DRVR_ENABLE_DCHECK=ON -DCMAKE_CXX_FLAGS="$(FUZZ_FLAGS)" \
		-DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
	cmake --build $(FUZZ_DIR) -j $(JOBS) --target fuzz_scene fuzz_mesh
	FUZZ_SECONDS=$(FUZZ_SECONDS) tests/fuzz/run.sh $(FUZZ_DIR)

# A sweep of a few minutes: JSON into bench/results/, charts into bench/charts/. Three
# repetitions in random order, medians kept: on a shared machine the speed drifts over minutes,
# and interleaving spreads the drift over every benchmark alike.
# BM_Visibility: the frame chart's z-buffers, tracers and hybrids, without the brute-force and
# binary-BVH tracers, and without 10^7 triangles for llvmpipe and the hybrids (seconds a frame).
BENCH_FILTER ?= BM_Frame/(raster|softraster|raytrace|raytrace_bvh2|embree|raytrace_none)/(tessphere|soup)/[0-9]+/1024|BM_Frame/(hybrid|hybrid_soft)/(tessphere|soup)/[0-9]{3,7}/1024|BM_Visibility/(softraster|raytrace|embree)/(tessphere|soup)/[0-9]+/1024|BM_Visibility/(raster|hybrid|hybrid_soft)/(tessphere|soup)/[0-9]{3,7}/1024|BM_DepthComplexity|BM_Effects|BM_Mirrors|BM_CurvedMirrors|BM_Trace|BM_Build|BM_Threads|BM_WriteAovs
# On an AVX-512 machine the targets' rows run again with our kernels forced to AVX2 (and Embree
# held to AVX2 with them): targets.md gives that column beside the default's.
BENCH_TARGETS_FILTER ?= BM_Frame/(softraster|raster)/(tessphere/(100000|1000000)|soup/1000000)/1024/|BM_Frame/softraster/tessphere/10000000/1024/|BM_Frame/(raytrace|softraster|hybrid_soft)/tessphere/(100|10000|100000)/1024/|BM_Effects/(hybrid_soft/)?(primary|hard_shadows)/|BM_Trace/(bvh|embree)/|BM_TracePacket/(bvh|embree)/|BM_Build/(bvh|embree_medium)/(100000|1000000)/|BM_Threads|BM_WriteAovs/depth,id,normal,cost/
bench: build
	mkdir -p bench/results bench/charts
	$(BUILD_DIR)/bin/rvr_bench --benchmark_filter='$(BENCH_FILTER)' --benchmark_min_time=0.2 \
		--benchmark_repetitions=3 --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
		--benchmark_out=bench/results/latest.json --benchmark_out_format=json
	if grep -qw avx512f /proc/cpuinfo; then \
		RVR_ISA=avx2 $(BUILD_DIR)/bin/rvr_bench --benchmark_filter='$(BENCH_TARGETS_FILTER)' --benchmark_min_time=0.2 \
			--benchmark_repetitions=3 --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
			--benchmark_out=bench/results/latest-avx2.json --benchmark_out_format=json && \
		/usr/bin/python3 bench/plot.py bench/results/latest.json bench/charts bench/results/latest-avx2.json; \
	else /usr/bin/python3 bench/plot.py bench/results/latest.json bench/charts; fi

# The headline study (docs/cli.md#rvr-study-what-each-loop-order-costs-computed-with-confidence):
# occluders (depth complexity), tessphere (to 1.8×10^7 triangles) and soup (to 3.2×10^7, as far
# as the memory allows), one renderer per loop order, local mode, 1024 wide, within STUDY_BUDGET
# seconds of sweeping (about 80 minutes on 2 cores: docs/cli.md), into bench/study/; its study.md
# is pasted into bench/README.md. Occluders first: what a family leaves of its share goes to
# the next, and soup's largest points cost the most.
STUDY_BUDGET ?= 6000
study: build
	$(BUILD_DIR)/bin/rvr study builtin:occluders builtin:tessphere builtin:soup --width 1024 \
		--mode local --budget $(STUDY_BUDGET) -o bench/study
	/usr/bin/python3 bench/paste_study.py bench/study/study.md bench/README.md

format:
	clang-format -i $$(git ls-files '*.cpp' '*.h')

# clang-tidy 14 (.clang-tidy: bugprone-*, performance-*, readability-function-size at 120 lines,
# less the checks listed there as noise) over the project's translation units in the build's
# compile_commands.json, chosen by tools/lint_files.py: the paths matching LINT_FILES and not
# LINT_EXCLUDE (regular expressions; LINT_EXCLUDE empty: none left out). Any finding fails.
LINT_FILES ?= $(CURDIR)/(apps|core|scene_io|compare|raster|raytrace|hybrid|renderers|study|present|image_codec|bench)/
LINT_EXCLUDE ?=
# Then include-what-you-use on LINT_IWYU_DIRS (tools/iwyu.imp maps the libraries' and libstdc++'s
# internal headers to their public ones): any include to add or remove fails, and so does iwyu
# failing on a file (a fatal error or an assertion leaves the file unchecked).
LINT_IWYU_DIRS ?= apps core scene_io compare raster raytrace hybrid renderers study present image_codec bench python tests
lint: build
	run-clang-tidy-14 -p $(BUILD_DIR) -j $(JOBS) -quiet \
		$$(/usr/bin/python3 tools/lint_files.py $(BUILD_DIR)/compile_commands.json '$(LINT_FILES)' '$(LINT_EXCLUDE)')
	iwyu_tool -p $(BUILD_DIR) -j $(JOBS) $(LINT_IWYU_DIRS) -- -Xiwyu --no_fwd_decls -Xiwyu --cxx17ns \
		-Xiwyu --mapping_file=$(CURDIR)/tools/iwyu.imp > $(BUILD_DIR)/iwyu.txt 2>&1 || true
	@if grep -q 'should \(add\|remove\) these lines\|fatal error\|Assertion failed' $(BUILD_DIR)/iwyu.txt; then \
		cat $(BUILD_DIR)/iwyu.txt; echo "lint: include-what-you-use asks for changes in $(LINT_IWYU_DIRS)"; exit 1; fi

clean:
	rm -rf $(BUILD_DIR) $(SANITIZE_DIR) $(FUZZ_DIR) build-wheel dist rvr-out
