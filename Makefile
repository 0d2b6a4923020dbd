# The README's commands: `make demo` and `make test` do everything on a fresh Debian 12 machine.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
PACKAGES := cmake g++ make pkg-config libosmesa6-dev libglm-dev libopenimageio-dev \
	openimageio-tools libbenchmark-dev libgtest-dev libembree-dev libtbb-dev \
	nlohmann-json3-dev libcli11-dev libfmt-dev libassimp-dev python3-matplotlib

.PHONY: all deps build demo test bench clean format

all: build

deps:
	@missing=$$(for p in $(PACKAGES); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; done); \
	if [ -z "$$missing" ]; then echo "deps: all packages present"; exit 0; fi; \
	if [ "$$(id -u)" != 0 ]; then echo "deps: run as root: apt-get update && apt-get install -y $$missing"; exit 1; fi; \
	echo "deps: installing $$missing"; \
	apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing

build: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD_DIR) -j $(JOBS)

demo: build
	$(BUILD_DIR)/bin/rvr compare builtin:cornell -o rvr-out

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# A sweep of a few minutes: JSON into bench/results/, charts into bench/charts/.
BENCH_FILTER ?= BM_Frame/(raster|raytrace|embree|raytrace_none)/(tessphere|soup)/[0-9]+/1024|BM_DepthComplexity|BM_Effects|BM_Trace|BM_Build
bench: build
	mkdir -p bench/results bench/charts
	$(BUILD_DIR)/bin/rvr_bench --benchmark_filter='$(BENCH_FILTER)' --benchmark_min_time=0.2 \
		--benchmark_out=bench/results/latest.json --benchmark_out_format=json
	/usr/bin/python3 bench/plot.py bench/results/latest.json bench/charts

format:
	clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	rm -rf $(BUILD_DIR) rvr-out
