# sanguis top-level driver. The README's two commands are `make demo` and `make test`.
BUILD ?= build
JOBS ?= $(shell nproc)
CASE ?= cases/dem/dam-break-spheres.toml
OUT ?= output/demo

.PHONY: deps build demo test bench bench-deps validate-dem format format-check clean

deps:
	bash scripts/install-deps.sh

$(BUILD)/build.ninja:
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/build.ninja
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(BUILD)/app/sanguis run $(CASE) --output $(OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench-deps:
	bash scripts/install-deps.sh --bench

bench: bench-deps build
	bash bench/run_all.sh

validate-dem: build
	/usr/bin/python3 validation/dem/run_all.py --build $(BUILD)

format:
	find src app tests bench validation -name '*.hpp' -o -name '*.cpp' | xargs clang-format -i

# Lists every file clang-format would change and fails if there is one.
format-check:
	find src app tests bench validation -name '*.hpp' -o -name '*.cpp' | xargs clang-format --dry-run -Werror

clean:
	rm -rf $(BUILD)
