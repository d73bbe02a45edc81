# SABRE build. `make run` and `make check` do all the set-up on a fresh Debian 12 machine.
#   make            bin/sabre (optimised: -O3 -march=native)
#   make deps       install the missing Debian packages (compilers, MPI, HDF5, METIS, Python)
#   make check      check build (run-time checks, FPE traps) + unit tests + regression
#   make check-batch  the Slurm job chain on a real Slurm the test starts and stops
#                   (installs slurmctld, slurmd, slurm-client; needs root)
#   make run        the default deck, then VTK files and a PNG of its history
#   make verify     convergence studies against exact solutions (tables/plots for the manual),
#                   gas dynamics and elastic-plastic solids
#   make accuracy   error against wall time for every scheme choice (work-precision, Pareto):
#                   the 1D and ghost-fluid families (~3 min), then the Taylor bar (~20 min)
#   make accuracy-taylor  the Taylor-bar family alone (error against its finest run)
#   make bench      3D gas-dynamics benchmark on 1 and 2 ranks with the STREAM triad
#   make clean

SHELL := /bin/bash
FC := mpif90
HDF5_INC := /usr/include/hdf5/openmpi
HDF5_LIB := /usr/lib/x86_64-linux-gnu/hdf5/openmpi
LIBS := -L$(HDF5_LIB) -lhdf5_fortran -lhdf5 -lmetis
PY := /usr/bin/python3
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMPI_MCA_rmaps_base_oversubscribe := 1
# mpirun otherwise waits a 1 s kill round after any rank exits non-zero (a bad deck)
export OMPI_MCA_odls_base_sigkill_timeout := 0

STD_FLAGS := -std=f2018 -ffree-line-length-132 -I$(HDF5_INC)
REL_FLAGS := $(STD_FLAGS) -O3 -march=native -g -fno-backtrace
# -Wno-maybe-uninitialized: gfortran 12 reports the hidden length of deferred-length
# character results as "may be used uninitialized" at -O1 (false positives)
CHK_FLAGS := $(STD_FLAGS) -O1 -g -Wall -Wextra -Wimplicit-interface -Werror -fcheck=all \
             -ffpe-trap=invalid,zero,overflow -fbacktrace -Wno-maybe-uninitialized

# modules in dependency order (a module only uses those before it)
MODULES := core/m_kinds parallel/m_comm core/m_errors core/m_signals core/m_config core/m_state \
  strength/m_yield strength/m_plasticity \
  core/m_timers grid/m_layout grid/m_blocks parallel/m_partition parallel/m_halo \
  grid/m_boundary eos/m_eos numerics/m_reconstruct \
  levelset/m_levelset_derivatives levelset/m_levelset_advect levelset/m_levelset_reinit \
  levelset/m_levelset_geometry levelset/m_levelset_bodies numerics/m_flux numerics/m_euler \
  gfm/m_gfm_probe gfm/m_gfm_stress gfm/m_gfm_mvi gfm/m_gfm_mri gfm/m_gfm_mmi gfm/m_gfm gfm/m_gfm_conserve \
  scene/m_scene strength/m_material_library io/m_deck_text io/m_deck_parse io/m_deck_values \
  io/m_deck_schema io/m_deck_check io/m_deck_write io/m_deck io/m_history io/m_hdf5_io io/m_xdmf
DRIVER := m_simulation m_output m_timeloop
SRC := $(addprefix modules/,$(addsuffix .f90,$(MODULES))) \
       $(addprefix src/,$(addsuffix .f90,$(DRIVER)))
REL_OBJ := $(patsubst %.f90,build/rel/%.o,$(SRC))
CHK_OBJ := $(patsubst %.f90,build/chk/%.o,$(SRC))
UNIT := test_eos test_reconstruct test_flux test_halo test_hdf5 test_strength test_levelset test_gfm
UNIT_BIN := $(addprefix bin/,$(UNIT))

.PHONY: all deps check check-batch run verify bench clean unit accuracy accuracy-taylor stability
all: bin/sabre

bin/sabre: $(REL_OBJ) build/rel/src/sabre.o | bin
	$(FC) $(REL_FLAGS) -o $@ $^ $(LIBS)

bin/sabre-check: $(CHK_OBJ) build/chk/src/sabre.o | bin
	$(FC) $(CHK_FLAGS) -o $@ $^ $(LIBS)

bin/test_%: regress/unit/test_%.f90 $(CHK_OBJ) | bin
	$(FC) $(CHK_FLAGS) -Jbuild/chk/mod -o $@ $< $(CHK_OBJ) $(LIBS)

# serial module build: each object depends on every module before it in the list
build/rel/%.o: %.f90
	@mkdir -p $(dir $@) build/rel/mod
	$(FC) $(REL_FLAGS) -Jbuild/rel/mod -c $< -o $@
build/chk/%.o: %.f90
	@mkdir -p $(dir $@) build/chk/mod
	$(FC) $(CHK_FLAGS) -Jbuild/chk/mod -c $< -o $@

# each object depends on the one before it in the list: modules build in order, and a
# changed module rebuilds everything that may use it
prev :=
$(foreach o,$(REL_OBJ) build/rel/src/sabre.o,$(if $(prev),$(eval $(o): $(prev)))$(eval prev := $(o)))
prev :=
$(foreach o,$(CHK_OBJ) build/chk/src/sabre.o,$(if $(prev),$(eval $(o): $(prev)))$(eval prev := $(o)))
$(REL_OBJ) $(CHK_OBJ): Makefile

bin:
	@mkdir -p bin

deps:
	@tools/install-deps

unit: $(UNIT_BIN)

check: deps
	$(MAKE) bin/sabre-check unit bin/sabre
	SABRE=bin/sabre-check $(PY) regress/run

# tools/batch/test-slurm: a time-limited job and a signalled one, each requeued until done,
# bit-identical to an uninterrupted run (the PBS chain is tested in make check)
check-batch: deps
	@tools/install-deps batch
	$(MAKE) bin/sabre
	tools/batch/test-slurm

run: deps
	$(MAKE) bin/sabre
	@tools/run-default

verify: deps
	$(MAKE) bin/sabre
	$(PY) tools/verify
	$(PY) tools/verify_strength

accuracy: deps
	$(MAKE) bin/sabre
	$(PY) tools/accuracy
	$(PY) tools/accuracy --families taylor_bar

# 18 runs on 2 ranks and the 0.075 mm reference (8 min; re-used while bin/sabre is unchanged)
accuracy-taylor: deps
	$(MAKE) bin/sabre
	$(PY) tools/accuracy --families taylor_bar

# the stability suite of hard cases (issue 5 section 2; manual/stability.md)
stability: deps
	$(MAKE) bin/sabre
	$(PY) tools/stability

bench: deps
	$(MAKE) bin/sabre bin/stream_triad
	$(PY) tools/bench

bin/stream_triad: tools/stream_triad.f90 | bin
	gfortran -O3 -march=native -fopenmp -o $@ $<

clean:
	rm -rf build bin regress/out
