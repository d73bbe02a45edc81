!> SABRE: Eulerian sharp-interface hydrocode. Usage:
!>   bin/sabre DECK [group.variable=value ...]
!>   mpirun -np N bin/sabre DECK ...
!> Reads and validates the deck, sets up blocks over the ranks, runs the time loop and writes
!> out_dir/run.log, history.csv, plot files and checkpoints (manual/user-guide.md).
program sabre
  use, intrinsic :: iso_fortran_env, only: compiler_version, compiler_options
  use m_kinds, only: wp, i8, path_len, line_len
  use m_config, only: config_t
  use m_comm, only: comm_init, comm_exit, comm_size, comm_wtime, comm_sum, comm_min, &
    comm_max, comm_rank
  use m_errors, only: log_open, log_close, log_line
  use m_deck, only: deck_read, deck_prepare_output
  use m_hdf5_io, only: h5_init, h5_finalize
  use m_simulation, only: sim_t, sim_setup, sim_paint_initial_state
  use m_output, only: output_restart
  use m_timeloop, only: run_time_loop
  use m_timers, only: timer_total, memory_kb
  use m_signals, only: signals_catch, exit_stopped
  implicit none
  type(config_t) :: cfg
  type(sim_t) :: sim
  character(len=path_len) :: deck_path
  character(len=path_len), allocatable :: overrides(:)
  character(len=:), allocatable :: deck_text
  integer :: nargs, k
  real(wp) :: wall, base_kb, loop_wall
  logical :: stopped

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
  call deck_prepare_output(cfg)
  call log_open(trim(cfg%out_dir) // '/run.log')
  sim%wall_start = wall
  call write_run_header(sim)
  deck_text = resolved_deck_text(trim(cfg%out_dir) // '/deck.nml')
  if (len_trim(cfg%restart) > 0) then
    call output_restart(sim, cfg%restart)
    call log_line('restart: from ' // trim(cfg%restart))
  else
    call sim_paint_initial_state(sim)
  end if
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
    integer :: u, n, ios
    text = ''
    if (comm_rank() /= 0) return
    open(newunit=u, file=path, access='stream', form='unformatted', action='read', iostat=ios)
    if (ios /= 0) return
    inquire(unit=u, size=n)
    deallocate(text)
    allocate(character(len=n) :: text)
    read(u, iostat=ios) text
    close(u)
  end function resolved_deck_text

  subroutine write_run_header(s)
    type(sim_t), intent(in) :: s
    character(len=line_len) :: line
    integer :: nb, k, l
    call log_line('SABRE run: ' // trim(s%cfg%title))
    call log_line('deck: ' // trim(s%cfg%deck_file) // '  (resolved copy: ' // &
      trim(s%cfg%out_dir) // '/deck.nml)')
    call log_line('compiler: ' // compiler_version())
    call log_line('build flags: ' // compiler_options())
    nb = size(s%blocks)
    write(line, '(a,i0,a,3(i0,1x),a,3(i0,1x),a,i0,a)') 'grid: ', s%lay%ndim, 'D, cells ', &
      s%lay%cells, ', blocks of ', s%lay%bsize, '(', count(s%lay%active), ' active)'
    call log_line(line)
    write(line, '(a,i0,a,i0,a,i0)') 'ranks: ', comm_size(), '; blocks per rank: min ', &
      comm_min(nb), ', max ', comm_max(nb)
    call log_line(line)
    write(line, '(a,a,a,a,a,i0,a,f5.3)') 'numerics: scheme ', trim(s%cfg%scheme), ', flux ', &
      trim(s%cfg%flux), ', rk_order ', s%cfg%rk_order, ', cfl ', s%cfg%cfl
    call log_line(line)
    if (s%has_strength) call log_line('numerics: flux of eps_p and w_c ' // &
      trim(s%cfg%scalar_flux))
    if (s%has_strength .and. s%ls%n > 0) call log_line('numerics: S, eps_p, w_c across ' // &
      'surface faces: ' // trim(s%cfg%surface_flux))
    do k = 1, s%nphase
      write(line, '(a,i0,a)') 'phase ', k, ': material ' // trim(s%material(k)) // ' (eos ' // &
        trim(eos_name(s, k)) // ')'
      if (k == 1 .and. s%ls%base_flows) line = trim(line) // ', the base'
      do l = 1, s%ls%n
        if (s%ls%phase(l) == k) line = trim(line) // ', body ' // trim(s%ls%name(l))
      end do
      call log_line(line)
    end do
    call log_line('effects: strength ' // trim(s%strength_reason))
    if (s%has_strength .and. s%cfg%thermal) then
      call log_line('effects: thermal on: temperature from the EOS less elastic and stored ' // &
        'work; Taylor-Quinney heating; Johnson-Cook softening where the model has it')
    else if (s%has_strength) then
      call log_line('effects: thermal off: &physics thermal = .false. or no material needs ' // &
        'it; the yield stress sees the reference temperature')
    else
      call log_line('effects: thermal off: no strength (a gas carries its temperature in e)')
    end if
    call log_line('effects: heat conduction off, reaction off (not in this version)')
    call log_line('effects: interfaces ' // trim(interfaces_reason(s)))
    if (s%ls%n > 0 .and. s%has_strength) call log_line('gfm: conservation fix ' // &
      trim(s%fix_reason))
    if (s%has_strength) then
      write(line, '(a,i0,a)') 'state: ', s%nvar, ' variables per cell (rho, rho u, rho v, ' // &
        'rho w, rho E, rho S (6), rho eps_p, rho w_c'
    else
      write(line, '(a,i0,a)') 'state: ', s%nvar, ' variables per cell (rho, rho u, rho v, ' // &
        'rho w, rho E'
    end if
    if (s%nphase > 1) write(line, '(a,a,i0,a)') trim(line), ' per phase x ', s%nphase, ' phases'
    if (s%ls%n > 0) write(line, '(a,a,i0,a)') trim(line), '; ', s%ls%n, ' level sets'
    line = trim(line) // ')'
    call log_line(line)
  end subroutine write_run_header

  !> 'on: ...' with the level-set bodies and their boundary classes, or 'off: ...'.
  function interfaces_reason(s) result(text)
    type(sim_t), intent(in) :: s
    character(len=line_len) :: text
    character(len=*), parameter :: class_name(3) = [character(len=24) :: &
      'free surface / contact', 'void, free surface (MVI)', 'rigid (MRI)']
    integer :: l
    if (s%ls%n == 0) then
      text = 'off: no body of another material, void or rigid'
      return
    end if
    write(text, '(a,i0,a,i0,a,f4.2,a)') 'on: ', s%ls%n, ' level sets, probe ' // &
      trim(s%cfg%gfm_probe) // ', band ', s%cfg%band, ' cells, contact kappa ', &
      s%cfg%contact_kappa, ':'
    do l = 1, s%ls%n
      text = trim(text) // ' ' // trim(s%ls%name(l)) // ' ' // trim(class_name(s%ls%kind(l)))
      if (l < s%ls%n) text = trim(text) // ';'
    end do
  end function interfaces_reason

  function eos_name(s, p) result(name)
    type(sim_t), intent(in) :: s
    integer, intent(in) :: p
    character(len=32) :: name
    integer :: k
    name = ''
    do k = 1, s%cfg%n_materials
      if (s%cfg%materials(k)%name == s%material(p)) name = s%cfg%materials(k)%eos
    end do
  end function eos_name

  subroutine write_run_footer(s, elapsed, loop, base)
    type(sim_t), intent(inout) :: s
    real(wp), intent(in) :: elapsed, loop, base
    character(len=line_len) :: line
    integer(i8) :: cs, nfall
    real(wp) :: cells, peak, base_sum, arrays, work
    cs = comm_sum(s%cell_steps)
    nfall = comm_sum(s%fallback_faces)
    write(line, '(a,i0,a,es14.7,a,i0,a,i0,a)') 'end: step ', s%step, ', time ', s%time, &
      ', first-order fallback faces ', nfall, ' in all, ', s%first_order_steps, &
      ' steps recomputed at first order'
    call log_line(line)
    write(line, '(a,i0,a)') 'end: ', comm_sum(s%cells_low), ' cells recomputed with ' // &
      'first-order faces by the cell-local fallback'
    call log_line(line)
    if (s%ls%n > 0) then
      write(line, '(a,i0,a,i0,a,i0,a,i0,a,i0,a,i0,a,i0,a)') 'gfm: ', &
        comm_sum(s%gcount%ghosts), ' ghost fills: ', comm_sum(s%gcount%trilinear), &
        ' trilinear (', comm_sum(s%gcount%incomplete), ' with an incomplete stencil), ', &
        comm_sum(s%gcount%least_squares), ' least squares, ', comm_sum(s%gcount%mean), &
        ' mean of neighbours, ', comm_sum(s%gcount%unfilled), ' without a real neighbour, ', &
        comm_sum(s%gcount%limited), ' ghost pressures limited'
      call log_line(line)
      write(line, '(a,i0,a,i0,a)') 'gfm: ', comm_sum(s%gcount%mmi), &
        ' ghosts across a material-material interface (MMI), ', &
        comm_sum(s%gcount%separated), ' contact ghosts in tension treated as free surfaces'
      call log_line(line)
      write(line, '(a,i0,a)') 'gfm: ', comm_sum(s%gcount%debris), ' inadmissible cells ' // &
        'within 2 cells of a body surface taken out of the body as debris'
      call log_line(line)
      if (s%fix_mass) then
        write(line, '(a,es11.4,a,f8.4,a,es11.4,a,f8.4,a,i0,a)') 'gfm: conservation fix ' // &
          'took out ', sum(s%fixed(1, :)), ' kg (', 100 * sum(s%fixed(1, :)) / s%content0(1), &
          ' % of the solids'' mass) and ', sum(s%fixed(2, :)), ' J (', &
          100 * sum(s%fixed(2, :)) / s%content0(2), ' % of their energy); ', s%fix_clamped, &
          ' fixes held to a tenth of the surface content'
        call log_line(line)
        write(line, '(a,i0,a)') 'gfm: conservation fix left aside in ', s%fix_aside, &
          ' steps when a solid crossed an open (outflow) side of the domain'
        call log_line(line)
      end if
      write(line, '(a,f9.3,a,f9.3,a)') 'gfm: ghost fill ', &
        comm_max(timer_total(s%timers, 'gfm')), ' s, reinitialisation ', &
        comm_max(timer_total(s%timers, 'reinit')), ' s'
      call log_line(line)
    end if
    write(line, '(a,f10.3,a,f9.3,a,f9.3,a,f9.3,a,f9.3,a)') 'wall time ', elapsed, &
      ' s: fluxes ', comm_max(timer_total(s%timers, 'fluxes')), ' s, halo+bc ', &
      comm_max(timer_total(s%timers, 'halo')), ' s, dt ', &
      comm_max(timer_total(s%timers, 'dt')), ' s, output ', &
      comm_max(timer_total(s%timers, 'output')), ' s'
    call log_line(line)
    write(line, '(a,es11.4,a,es11.4,a)') 'cost: ', real(cs, wp), ' cell-steps, ', &
      real(cs, wp) / max(elapsed, 1.0e-9_wp) / comm_size(), ' cell-steps per second per rank'
    call log_line(line)
    write(line, '(a,es11.4,a,f10.3,a)') 'loop: ', real(cs, wp), ' cell-steps in ', loop, ' s'
    call log_line(line)
    ! work per rank: a rank with less waits for the others inside halo+bc
    work = timer_total(s%timers, 'fluxes') + timer_total(s%timers, 'gfm') + &
      timer_total(s%timers, 'reinit') + timer_total(s%timers, 'dt')
    write(line, '(a,f10.3,a,f10.3,a)') 'balance: work per rank (fluxes, ghost fill, ' // &
      'reinitialisation, dt) min ', comm_min(work), ' s, max ', comm_max(work), ' s'
    call log_line(line)
    cells = real(count(s%lay%active), wp) * product(s%lay%bsize)
    peak = comm_sum(memory_kb('VmHWM'))
    base_sum = comm_sum(base)
    arrays = 8.0_wp * s%nvar * (product(s%lay%bsize + 2 * s%lay%ng) &
      + 2 * product(s%lay%bsize)) / product(s%lay%bsize)
    write(line, '(a,f10.1,a,f10.1,a,f8.1,a)') 'memory: peak resident ', peak / 1024, &
      ' MB over all ranks (', base_sum / 1024, ' MB before the grid), ', &
      (peak - base_sum) * 1024 / cells, ' bytes per cell above the baseline'
    call log_line(line)
    write(line, '(a,f8.1,a)') 'memory: solver arrays ', arrays, ' bytes per cell (state with ' // &
      'halo, start-of-step copy, right-hand side)'
    call log_line(line)
    call log_line('results: ' // trim(s%cfg%out_dir))
  end subroutine write_run_footer

end program sabre
