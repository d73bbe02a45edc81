!> SABRE: Eulerian sharp-interface hydrocode. Usage:
!>   bin/sabre DECK [group.variable=value ...]
!>   mpirun -np N bin/sabre DECK ...
!> Reads and validates the deck, sets up blocks over the ranks, runs the time loop and writes
!> out_dir/run.log, run.json, history.csv, plot files and checkpoints (manual/user-guide.md).
!> Everything the deck points at (its values, the memory it needs, the restart file) is
!> checked before out_dir is created.
program sabre
  use m_kinds, only: wp, path_len, line_len
  use m_text, only: file_text
  use m_config, only: config_t
  use m_comm, only: comm_init, comm_exit, comm_wtime, comm_rank
  use m_errors, only: log_open, log_close, log_line
  use m_deck, only: deck_read
  use m_output, only: output_prepare
  use m_hdf5_io, only: h5_init, h5_finalize
  use m_simulation, only: sim_t, sim_setup, sim_paint_initial_state
  use m_gfm_stage, only: phase_states, states_start
  use m_checkpoint, only: output_restart, output_restart_check
  use m_timeloop, only: run_time_loop
  use m_timers, only: memory_kb
  use m_run_log, only: write_run_header, write_run_footer
  use m_signals, only: signals_catch, exit_stopped
  implicit none
  type(config_t) :: cfg
  type(sim_t) :: sim
  character(len=path_len) :: deck_path
  character(len=path_len), allocatable :: overrides(:)
  character(len=:), allocatable :: deck_text
  integer :: nargs, k
  real(wp) :: wall, base_kb, loop_wall
  logical :: stopped, bad_start

  call comm_init()
  call signals_catch()
  wall = comm_wtime()
  nargs = command_argument_count()
  if (nargs < 1) then
    call usage()
    call comm_exit(2)
  end if
  call get_command_argument(1, deck_path)
  if (deck_path == '--help' .or. deck_path == '-h') then
    call usage()
    call comm_exit(0)
  end if
  allocate(overrides(nargs - 1))
  do k = 2, nargs
    call get_command_argument(k, overrides(k - 1))
  end do
  call h5_init()
  base_kb = memory_kb('VmRSS')
  call deck_read(trim(deck_path), overrides, cfg)
  call sim_setup(cfg, sim)
  if (len_trim(cfg%restart) > 0) call output_restart_check(sim, cfg%restart)
  call output_prepare(cfg)
  call log_open(trim(cfg%out_dir) // '/run.log')
  sim%clk%wall_start = wall
  call write_run_header(sim)
  deck_text = resolved_deck_text(trim(cfg%out_dir) // '/deck.nml')
  if (len_trim(cfg%restart) > 0) then
    call output_restart(sim, cfg%restart)
    call log_line('restart: from ' // trim(cfg%restart))
  else
    call sim_paint_initial_state(sim)
  end if
  ! a cut-cell phase takes its content from the states (m_gfm_cut; nothing without one)
  bad_start = .false.
  call phase_states(sim%gf, sim%cut, sim%ls, sim%ph, sim%plan, sim%lay, sim%bc, sim%blocks, &
    sim%clk%time, 0.0_wp, sim%cfg%rk_order, .false., states_start, bad_start)
  loop_wall = comm_wtime()
  call run_time_loop(sim, deck_text, stopped)
  loop_wall = comm_wtime() - loop_wall
  call write_run_footer(sim, comm_wtime() - wall, loop_wall, base_kb)
  call log_close()
  call h5_finalize()
  ! a run stopped before its end says so to its job script (tools/batch)
  if (stopped) call comm_exit(exit_stopped)
  call comm_exit(0)

contains

  subroutine usage()
    if (comm_rank() /= 0) return
    write(6, '(a)') 'usage: sabre DECK [group.variable=value ...]'
    write(6, '(a)') '  runs the input deck DECK (Fortran namelists, see manual/user-guide.md);'
    write(6, '(a)') '  overrides such as run.out_dir=''x'' domain.cells=400,1,1 follow the deck.'
  end subroutine usage

  !> The resolved deck as one string (rank 0 reads it; stored in checkpoints).
  function resolved_deck_text(path) result(text)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: text
    character(len=line_len) :: msg
    integer :: ios
    text = ''
    msg = ''
    if (comm_rank() == 0) call file_text(path, text, ios, msg)
  end function resolved_deck_text

end program sabre
