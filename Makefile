# SABRE build. `make run` and `make check` do all the set-up on a fresh Debian 12 machine.
#   make            bin/sabre (optimised: -O3 -march=native)
#   make COMM=caf   bin/sabre-caf: the coarray back end of comm (OpenCoarrays; run by cafrun)
#   make deps       install the missing Debian packages (compilers, MPI, HDF5, METIS, Python)
#   make check      check build (run-time checks, FPE traps) + unit tests + regression,
#                   then the coarray check build's pass, bit-identical to the MPI build
#   make check-batch  the Slurm job chain on a real Slurm the test starts and stops
#                   (installs slurmctld, slurmd, slurm-client; needs root)
#   make run        the default deck, then VTK files and a PNG of its history
#   make verify     convergence studies against exact solutions (tables/plots for the manual),
#                   gas dynamics and elastic-plastic solids
#   make accuracy   error against wall time for every scheme choice (work-precision, Pareto):
#                   the 1D and ghost-fluid families (~3 min), then the Taylor bar (~20 min)
#   make accuracy-taylor  the Taylor-bar family alone (error against its finest run)
#   make bench      3D gas-dynamics benchmark on 1 and 2 ranks with the STREAM triad
#                   (CLOVERLEAF=path/to/clover_leaf make bench: CloverLeaf3D beside it)
#   CLOVERLEAF=path/to/clover_leaf make blast-compare   3D Sedov work-precision against CloverLeaf3D
#   make clean

SHELL := /bin/bash
FC := mpif90
HDF5_INC := /usr/include/hdf5/openmpi
HDF5_LIB := /usr/lib/x86_64-linux-gnu/hdf5/openmpi
# FFTW 3 (libfftw3-dev): the random-field scene generator (modules/scene/m_scene_field)
FFTW_INC := /usr/include
LIBS := -L$(HDF5_LIB) -lhdf5_fortran -lhdf5 -lmetis -lfftw3
PY := /usr/bin/python3
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMPI_MCA_rmaps_base_oversubscribe := 1
# mpirun otherwise waits a 1 s kill round after any rank exits non-zero (a bad deck)
export OMPI_MCA_odls_base_sigkill_timeout := 0

STD_FLAGS := -std=f2018 -ffree-line-length-132 -I$(HDF5_INC) -I$(FFTW_INC)
REL_FLAGS := $(STD_FLAGS) -O3 -march=native -g -fno-backtrace
# -Wno-maybe-uninitialized: gfortran 12 reports the hidden length of deferred-length
# character results as "may be used uninitialized" at -O1 (false positives)
CHK_FLAGS := $(STD_FLAGS) -O1 -g -Wall -Wextra -Wimplicit-interface -Werror -fcheck=all \
             -ffpe-trap=invalid,zero,overflow -fbacktrace -Wno-maybe-uninitialized

# modules in dependency order (a module only uses those before it)
MODULES := core/m_kinds parallel/m_comm core/m_errors core/m_text core/m_signals core/m_config \
  core/m_state strength/m_yield strength/m_plasticity \
  core/m_timers grid/m_layout grid/m_blocks grid/m_tiles parallel/m_partition parallel/m_balance \
  parallel/m_halo \
  eos/m_eos numerics/m_reaction numerics/m_phases numerics/m_conduction grid/m_boundary numerics/m_reconstruct \
  numerics/m_characteristic \
  levelset/m_levelset_derivatives levelset/m_levelset_advect levelset/m_levelset_reinit \
  levelset/m_levelset_geometry levelset/m_levelset_bodies levelset/m_levelset_motion \
  levelset/m_levelset_cut scene/m_scene_generate scene/m_scene_grains scene/m_scene_field scene/m_scene numerics/m_flux numerics/m_elastoplastic \
  numerics/m_runge_kutta numerics/m_euler_faces numerics/m_euler numerics/m_fallback gfm/m_gfm_probe gfm/m_gfm_stress gfm/m_gfm_mvi \
  gfm/m_gfm_mri gfm/m_gfm_mmi gfm/m_gfm gfm/m_gfm_conserve \
  gfm/m_gfm_cut_work gfm/m_gfm_cut_box gfm/m_gfm_cut_cells gfm/m_gfm_cut_close gfm/m_gfm_cut_geometry gfm/m_gfm_cut gfm/m_gfm_cut_setup gfm/m_gfm_cut_budget gfm/m_gfm_cut_contact gfm/m_gfm_stage gfm/m_phase_heat strength/m_material_library numerics/m_numerics_defaults \
  io/m_deck_parse io/m_deck_schema io/m_plot_fields io/m_deck_check io/m_deck io/m_history \
  io/m_hdf5_file io/m_hdf5_attr io/m_hdf5_io io/m_xdmf io/m_json
DRIVER := m_hotspot m_memory m_simulation m_output m_checkpoint m_schedule m_run_report m_run_log \
  m_step m_step_after m_rebalance m_timeloop
SRC := $(addprefix modules/,$(addsuffix .f90,$(MODULES))) \
       $(addprefix src/,$(addsuffix .f90,$(DRIVER)))
# comm back end (manual/design.md section 3): COMM=mpi (default) builds bin/sabre and
# bin/sabre-check as always; `make COMM=caf` builds bin/sabre-caf, the coarray back end
# (OpenCoarrays' caf), in build/rel-caf and build/chk-caf, beside the MPI build. The back
# end compiles just before m_comm, which all other modules use.
COMM ?= mpi
CAF_FC := caf
CAF_SRC := $(subst modules/parallel/m_comm.f90,modules/parallel/m_comm_caf.f90 \
  modules/parallel/m_comm.f90,$(SRC))
SRC := $(subst modules/parallel/m_comm.f90,modules/parallel/m_comm_mpi.f90 \
  modules/parallel/m_comm.f90,$(SRC))
REL_OBJ := $(patsubst %.f90,build/rel/%.o,$(SRC))
CHK_OBJ := $(patsubst %.f90,build/chk/%.o,$(SRC))
UNIT := test_eos test_reconstruct test_characteristic test_flux test_halo test_hdf5 test_strength test_levelset \
  test_gfm test_euler test_boundary test_partition test_levelset_cut test_hotspot test_reaction test_scene
UNIT_BIN := $(addprefix bin/,$(UNIT))

.PHONY: all deps check check-caf check-batch run verify bench blast-compare clean unit accuracy accuracy-taylor stability
all: $(if $(filter caf,$(COMM)),bin/sabre-caf,bin/sabre)

bin/sabre: $(REL_OBJ) build/rel/src/sabre.o | bin
	$(FC) $(REL_FLAGS) -o $@ $^ $(LIBS)

bin/sabre-check: $(CHK_OBJ) build/chk/src/sabre.o | bin
	$(FC) $(CHK_FLAGS) -o $@ $^ $(LIBS)

# the unit tests' shared assertions (regress/unit/m_test_check.f90), compiled once per build
TEST_CHECK := build/chk/regress/unit/m_test_check.o
$(TEST_CHECK): $(CHK_OBJ)

bin/test_%: regress/unit/test_%.f90 $(CHK_OBJ) $(TEST_CHECK) | bin
	$(FC) $(CHK_FLAGS) -Jbuild/chk/mod -o $@ $< $(CHK_OBJ) $(TEST_CHECK) $(LIBS)

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

# ---- the coarray build (COMM=caf): the same sources with m_comm_caf, compiled by caf ----
CAF_REL_OBJ := $(patsubst %.f90,build/rel-caf/%.o,$(CAF_SRC))
CAF_CHK_OBJ := $(patsubst %.f90,build/chk-caf/%.o,$(CAF_SRC))
CAF_UNIT_BIN := bin/test_halo-caf
# cases the coarray build runs in `make check` (regress/run --identical-to: every plot file
# of every run bit-identical to the MPI build's): every case that runs the solver (kinds run,
# ranks, restart: 54, about 8 minutes on 2 cores) and the deck errors. Left out: the command
# cases that drive tools (their solver runs are MPI-build runs). Evaluated when used.
CAF_CASES = $(shell $(PY) regress/run --list 2>/dev/null | \
  awk '$$2 == "run" || $$2 == "ranks" || $$2 == "restart" {print $$1}') bad_decks
# a 1-image coarray run (a singleton, as regress/run starts np = 1) cannot use Open MPI's
# UCX one-sided component (MPI_ERR_WIN at start-up): any other (Open MPI picks; pt2pt works)
CAF_ENV := OMPI_MCA_osc=^ucx

bin/sabre-caf: $(CAF_REL_OBJ) build/rel-caf/src/sabre.o | bin
	$(CAF_FC) $(REL_FLAGS) -o $@ $^ $(LIBS)

bin/sabre-caf-check: $(CAF_CHK_OBJ) build/chk-caf/src/sabre.o | bin
	$(CAF_FC) $(CHK_FLAGS) -o $@ $^ $(LIBS)

CAF_TEST_CHECK := build/chk-caf/regress/unit/m_test_check.o
$(CAF_TEST_CHECK): $(CAF_CHK_OBJ)

bin/test_%-caf: regress/unit/test_%.f90 $(CAF_CHK_OBJ) $(CAF_TEST_CHECK) | bin
	$(CAF_FC) $(CHK_FLAGS) -Jbuild/chk-caf/mod -o $@ $< $(CAF_CHK_OBJ) $(CAF_TEST_CHECK) $(LIBS)

build/rel-caf/%.o: %.f90
	@mkdir -p $(dir $@) build/rel-caf/mod
	$(CAF_FC) $(REL_FLAGS) -Jbuild/rel-caf/mod -c $< -o $@
build/chk-caf/%.o: %.f90
	@mkdir -p $(dir $@) build/chk-caf/mod
	$(CAF_FC) $(CHK_FLAGS) -Jbuild/chk-caf/mod -c $< -o $@

prev :=
$(foreach o,$(CAF_REL_OBJ) build/rel-caf/src/sabre.o,$(if $(prev),$(eval $(o): $(prev)))$(eval prev := $(o)))
prev :=
$(foreach o,$(CAF_CHK_OBJ) build/chk-caf/src/sabre.o,$(if $(prev),$(eval $(o): $(prev)))$(eval prev := $(o)))
$(CAF_REL_OBJ) $(CAF_CHK_OBJ): Makefile
# both comm back ends include their one interface
$(filter %/m_comm_mpi.o %/m_comm_caf.o,$(REL_OBJ) $(CHK_OBJ) $(CAF_REL_OBJ) $(CAF_CHK_OBJ)): \
  modules/parallel/m_comm_backend.inc modules/parallel/m_comm_backend_error.inc

# the coarray build's regression pass, after the MPI pass (whose outputs it compares with)
check-caf:
	$(MAKE) bin/sabre-caf-check
	$(CAF_ENV) SABRE=bin/sabre-caf-check MPIRUN=cafrun $(PY) regress/run \
	  --out regress/out/caf --identical-to regress/out --only $(CAF_CASES)

bin:
	@mkdir -p bin

deps:
	@tools/install-deps

unit: $(UNIT_BIN) $(CAF_UNIT_BIN)

check: deps
	$(MAKE) bin/sabre-check unit bin/sabre bin/sabre-caf-check
	SABRE=bin/sabre-check $(PY) regress/run
	$(MAKE) check-caf

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

blast-compare: deps
	@test -n "$(CLOVERLEAF)" || { echo 'blast-compare: set CLOVERLEAF=path/to/clover_leaf'; exit 2; }
	$(MAKE) bin/sabre
	$(PY) tools/blast_compare --fresh --cells 32,48,64,96 --figure manual/figures/blast_compare.png

bin/stream_triad: tools/stream_triad.f90 | bin
	gfortran -O3 -march=native -fopenmp -o $@ $<

clean:
	rm -rf build bin regress/out
