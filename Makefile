# Two commands do everything on a fresh machine with Python 3.11:
#   make demo   -> set up .venv (once) and run an ObjectNav mission in the built-in simulator
#   make test   -> set up .venv (once) and run the test suite
# The venv is rebuilt only when pyproject.toml changes (stamp file).
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.hiconav-installed
HOUSE ?= procthor:val/3
OUT ?= out/demo

.PHONY: demo test test-all bench setup clean

setup: $(STAMP)

$(STAMP): pyproject.toml setup.py
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	# torch first, pinned: the CPU build on disk; a later unpinned resolve would pull a CUDA build
	$(BIN)/python -m pip install --quiet "torch==2.13.0"
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	# MAVProxy for tests/drivers/test_drivers_mavproxy.py, without its dependencies: they pull
	# opencv-python, which clashes with our opencv-python-headless (pyserial is all it needs here)
	$(BIN)/python -m pip install --quiet --no-deps MAVProxy pyserial
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/hiconav run --house $(HOUSE) --seed 0 --out $(OUT) --record $(OUT)/mission.rrd

test: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

test-all: $(STAMP)
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	for b in benchmarks/*.py; do $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) out build *.egg-info
