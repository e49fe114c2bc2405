# Every target bootstraps the virtual environment on a fresh machine (python3 -m venv + pip install -e .[test]).
# `make test` also installs the Debian tools the tests need (Icarus Verilog; yosys-abc for the formal proofs;
# GTKWave + xvfb for the save-file checks) through scripts/system-deps.sh, or stops before pytest with the
# command that would; that check runs first, before the virtual environment is installed, so a machine without
# them learns it in a second.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
JOBS   ?= 2
# Static TLS for many Verilator builds loaded in one process (sim/runners/verilator/ctestbench.py, STATIC_TLS_ENV).
export GLIBC_TUNABLES ?= glibc.rtld.optional_static_tls=262144

.PHONY: all help venv system-deps test test-slow formal demo verilog waves bench resources timing clean distclean

all: help

help:
	@echo "make demo       run the main job on the bundled stereo pair -> build/demo/ (PNG frames, VCD, GTKWave save file)"
	@echo "make test       run the default test suite (Amaranth simulator + cocotb on Verilator and Icarus)"
	@echo "make test-slow  run the slow, full-resolution tests"
	@echo "make formal     prove every block's safety properties (table: block, properties, bound, time)"
	@echo "make verilog    write the board build (Verilog, UCF, ISE scripts) to build/genesys/"
	@echo "make waves      write the display-path VCD + GTKWave save file and print how to open them"
	@echo "make bench      run the benchmarks in bench/ and print their figures"
	@echo "make resources  Yosys synth_xilinx resource estimate of the top level"
	@echo "make timing     static timing estimate per clock domain; exit status 1 on negative slack"

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

venv: $(STAMP)

system-deps:
	@scripts/system-deps.sh

test: system-deps $(STAMP)
	$(PY) -m pytest -n $(JOBS) -q

test-slow: system-deps $(STAMP)
	$(PY) -m pytest -q -n 2 -m "slow and not hours"

formal: system-deps $(STAMP)
	$(PY) -m sim.formal

demo: $(STAMP)
	$(PY) -m stereodepth demo

verilog: $(STAMP)
	$(PY) -m stereodepth verilog

waves: $(STAMP)
	$(PY) -m stereodepth waves

bench: $(STAMP)
	$(PY) -m bench

resources: $(STAMP)
	$(PY) -m stereodepth resources

timing: $(STAMP)
	$(PY) -m stereodepth timing

clean:
	rm -rf build .pytest_cache .hypothesis

distclean: clean
	rm -rf $(VENV) *.egg-info
