# The two commands of the README: `make demo` and `make test`. Both set up what they need first.
# Set-up is idempotent: the venv, pip installs, the interface packages and the Debian packages
# are only (re)done when their inputs change or they are missing (the stamps below).
#   setup-demo: the venv with rclpy and the runtime dependencies, the Debian build tools (CMake,
#               a C/C++ compiler), the interface package the demo needs (tf2_msgs); what
#               `make demo` needs.
#   setup:      that, plus the other interface packages, the `dev` extra (pytest, ruff, mypy),
#               the Debian ign-transport tools the interop tests talk to and clang-14 for the
#               fuzzers; what `make test`, `make fuzz` and `make soak` need.

SHELL := /bin/bash
PYTHON ?= python3
# One venv per interpreter: `make test PYTHON=python3.12` sets up and tests in .venv-python3.12.
VENV ?= $(if $(filter python3,$(PYTHON)),.venv,.venv-$(notdir $(PYTHON)))
PY := $(VENV)/bin/python
DEMO_STAMP := $(VENV)/.ros_gz_bridge_py-setup-demo
STAMP := $(VENV)/.ros_gz_bridge_py-setup
BENCH_STAMP := $(VENV)/.ros_gz_bridge_py-bench
LOOPBACK := ../shared/tools/loopback-env
# Keep ROS, Gazebo Transport and Zenoh traffic on this host (see DEVELOPERS.md).
WITH_LOOPBACK := if [ -f $(LOOPBACK) ]; then source $(LOOPBACK); else source tools/loopback-env; fi;

.PHONY: setup-demo setup test lint typecheck unit demo bench soak attacks fuzz clean

# The package's bytecode, brought up to date on every run (0.2 s when it is): an editable install
# has none, and where PYTHONDONTWRITEBYTECODE is set (as on the project machines) every bridge
# process would compile the whole package again (3 entries: the last channel 1.5 s after start
# instead of 0.8 s, median of 6 alternated rounds, load average 5).
BYTECODE := $(PY) -m compileall -q ros_gz_bridge_py

setup-demo: $(DEMO_STAMP)
	@$(BYTECODE)

# The C++ test peer (testing/peer), built once per version of its sources; a second run only
# checks that it is (testing/gzpeer.py).
setup: $(STAMP)
	@$(BYTECODE)
	@$(PY) -m testing.gzpeer

# The pinned requirements first (pyproject.toml's, without the package: tools/requirements.py),
# then the editable package, whose native extension compiles, beside tf2_msgs's build.
$(DEMO_STAMP): pyproject.toml tools/requirements.py tools/apt_ensure.sh tools/apt_get.sh tools/setup_build.sh tools/setup_interfaces.sh $(shell find interfaces -type f 2>/dev/null)
	bash tools/setup_build.sh
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -r <($(PY) tools/requirements.py ros interfaces)
	$(PY) -m pip install --quiet --no-deps -e . & editable=$$!; \
	  bash tools/setup_interfaces.sh $(VENV) tf2_msgs; built=$$?; \
	  wait $$editable && exit $$built
	@touch $(DEMO_STAMP)

$(STAMP): $(DEMO_STAMP) tools/setup_peer.sh tools/setup_fuzz.sh tools/apt_get.sh
	$(PY) -m pip install --quiet -r <($(PY) tools/requirements.py --extras-only dev)
	bash tools/setup_interfaces.sh $(VENV)
	bash tools/setup_peer.sh
	bash tools/setup_fuzz.sh
	@touch $(STAMP)

lint: setup
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

typecheck: setup
	$(VENV)/bin/mypy ros_gz_bridge_py testing tests benchmarks tools examples

unit: setup
	$(WITH_LOOPBACK) $(PY) -m pytest -q tests benchmarks/tests

test: lint typecheck unit

demo: setup-demo
	$(WITH_LOOPBACK) $(PY) -m ros_gz_bridge_py.demo

# The benchmarks also need the `bench` extra (matplotlib, for the plots of BENCHMARKS.md and its reports).
$(BENCH_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -r <($(PY) tools/requirements.py --extras-only bench)
	@touch $(BENCH_STAMP)

bench: $(BENCH_STAMP)
	$(WITH_LOOPBACK) $(PY) -m benchmarks.run

# Ten minutes of mixed traffic and faults; writes SOAK.md (a short version runs in `make test`);
# then the fuzzing of `make fuzz`.
soak: setup
	$(WITH_LOOPBACK) $(PY) -m benchmarks.soak --seconds $${SOAK_SECONDS:-600}
	$(MAKE) --no-print-directory fuzz

# Hostile payloads beside real publishers, on both paths: the Attacks section of SOAK.md.
attacks: setup
	$(WITH_LOOPBACK) $(PY) -m benchmarks.attacks

# The native transcoders under libFuzzer with ASan and UBSan, then MSan, for FUZZ_SECONDS in all
# (600 by default; `make test` runs 60): tests/unit/native/test_fuzz.py, corpus in .build/fuzz.
fuzz: setup
	FUZZ_SECONDS=$${FUZZ_SECONDS:-600} $(PY) -m pytest -q tests/unit/native/test_fuzz.py

clean:
	rm -rf .build .pytest_cache .mypy_cache .ruff_cache
