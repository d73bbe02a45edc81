!> What a run tells its user besides its fields (manual/user-guide.md, "Output"): the
!> progress line printed while it runs, the facts gathered at its end (counts, timings,
!> memory, fallback and conservation-fix figures, reduced over the ranks once) that run.log's
!> last lines print, and run.json, the same facts for tools to read. The effects' reasons
!> that run.log's header gives are made here too, so that run.log and run.json say the same.
!> It neither runs the loop (m_timeloop) nor writes fields (m_output).
module m_run_report
  use, intrinsic :: iso_fortran_env, only: compiler_version, compiler_options
  use m_kinds, only: wp, i8, line_len
  use m_simulation, only: sim_t
  use m_memory, only: mem_parts
  use m_hotspot, only: hot_json
  use m_gfm, only: gfm_count_names, gfm_count_list
  use m_comm, only: comm_sum, comm_min, comm_max, comm_size, comm_wtime, comm_is_root
  use m_errors, only: log_line, log_flush
  use m_timers, only: timer_total, memory_kb
  use m_layout, only: active_cells
  use m_json, only: json_t, json_begin, json_end, json_object, json_close, json_put, &
    json_put_array, json_put_members, json_write
  implicit none
  private
  public :: progress_t, progress_start, progress_report
  public :: run_facts_t, run_facts, run_json_write, thermal_reason, interfaces_reason, &
    halo_line

  !> seconds of wall time between progress lines
  real(wp), parameter :: progress_every = 30.0_wp

  !> the clock of the progress line: where the loop started and when the last line went out
  type :: progress_t
    real(wp) :: wall0 = 0.0_wp, last = 0.0_wp, time0 = 0.0_wp
    integer :: step0 = 0
  end type progress_t

  !> the facts of a finished run, reduced over the ranks (the same on every rank)
  type :: run_facts_t
    integer :: step = 0, first_order_steps = 0, fix_clamped = 0, fix_aside = 0
    integer :: blocks_min = 0, blocks_max = 0   !< blocks per rank
    real(wp) :: time = 0.0_wp
    integer(i8) :: cell_steps = 0, fallback_faces = 0, cells_low = 0
    !> the ghost-fluid counts (m_gfm's gfm_count_names) summed over the ranks
    integer(i8) :: gfm(size(gfm_count_names)) = 0
    real(wp) :: gfm_s = 0.0_wp, reinit_s = 0.0_wp
    !> mass (kg) and energy (J) that the conservation fix took out, and as per cent of the
    !> solids' content at the start (NaN where that part is off)
    real(wp) :: fixed(2) = 0.0_wp, fixed_percent(2) = 0.0_wp
    real(wp) :: wall = 0.0_wp, loop = 0.0_wp, fluxes = 0.0_wp, halo = 0.0_wp, dt = 0.0_wp, &
      output = 0.0_wp, work_min = 0.0_wp, work_max = 0.0_wp
    !> bytes: peak resident memory over all ranks and of the largest rank, before the grid
    !> over all ranks; bytes per cell above that baseline; solver arrays per cell
    real(wp) :: peak = 0.0_wp, peak_rank = 0.0_wp, base = 0.0_wp, per_cell = 0.0_wp, &
      arrays_per_cell = 0.0_wp
    !> the halo exchanges of the time loop (m_halo's counts): its steps, and of the largest
    !> rank (1) and all ranks (2) the exchanges, the messages and bytes sent to other ranks,
    !> the bytes copied between blocks of one rank
    integer(i8) :: halo_steps = 0
    integer(i8), dimension(2) :: halo_exchanges = 0, halo_messages = 0, halo_bytes = 0, &
      halo_copy_bytes = 0
  end type run_facts_t

contains

  !> Start the progress clock at the loop's first step.
  subroutine progress_start(sim, pg)
    type(sim_t), intent(in) :: sim
    type(progress_t), intent(out) :: pg
    pg%wall0 = comm_wtime()
    pg%last = pg%wall0
    pg%time0 = sim%clk%time
    pg%step0 = sim%clk%step
  end subroutine progress_start

  !> Rank 0 prints, to stdout and run.log, at most every progress_every seconds and when
  !> last is set,
  !>   progress: step 1200, t 4.5000e-05, dt 3.7500e-08, 56.2 % of t_end, wall 30.1 s,
  !>   left 23.4 s, 1.234e+06 cell-steps/s
  !> (one line). The per cent (from t = 0, step 0) and the time left (from this run's
  !> start) are of t_end or max_steps, whichever the run reaches first; the rate counts the
  !> active cells of all ranks.
  subroutine progress_report(sim, pg, t_end, last)
    type(sim_t), intent(in) :: sim
    type(progress_t), intent(inout) :: pg
    real(wp), intent(in) :: t_end
    logical, intent(in) :: last
    character(len=line_len) :: line
    real(wp) :: now, done, left, rate, cells, share
    logical :: by_steps
    if (.not. comm_is_root()) return
    now = comm_wtime()
    if (.not. last .and. now - pg%last < progress_every) return
    pg%last = now
    done = 0.0_wp
    if (t_end < huge(1.0_wp) .and. t_end > pg%time0) &
      done = (sim%clk%time - pg%time0) / (t_end - pg%time0)
    if (sim%cfg%max_steps > pg%step0 .and. sim%cfg%max_steps < huge(1)) &
      done = max(done, real(sim%clk%step - pg%step0, wp) / (sim%cfg%max_steps - pg%step0))
    done = min(max(done, 0.0_wp), 1.0_wp)
    left = 0.0_wp
    if (done > 0.0_wp) left = (now - pg%wall0) * (1.0_wp - done) / done
    cells = active_cells(sim%lay)
    rate = cells * (sim%clk%step - pg%step0) / max(now - pg%wall0, 1.0e-9_wp)
    share = 0.0_wp
    if (t_end < huge(1.0_wp)) share = sim%clk%time / t_end
    by_steps = .false.
    if (sim%cfg%max_steps < huge(1)) then
      by_steps = real(sim%clk%step, wp) / max(sim%cfg%max_steps, 1) > share
      if (by_steps) share = real(sim%clk%step, wp) / max(sim%cfg%max_steps, 1)
    end if
    write(line, '(a,i0,14a)') 'progress: step ', sim%clk%step, &
      ', t ', sci(sim%clk%time, 4), ', dt ', sci(sim%clk%dt, 4), ', ', seconds(100.0_wp * share), &
      ' % of ' // trim(merge('max_steps', 't_end    ', by_steps)), ', wall ', &
      seconds(now - sim%clk%wall_start), ' s, left ', seconds(left), ' s, ', sci(rate, 3), &
      ' cell-steps/s'
    call log_line(line)
    call log_flush()
  end subroutine progress_report

  !> x as 1.2345e-05 (digits after the point)
  function sci(x, digits) result(r)
    real(wp), intent(in) :: x
    integer, intent(in) :: digits
    character(len=:), allocatable :: r
    character(len=32) :: buf, fmt
    write(fmt, '(a,i0,a,i0,a)') '(es', digits + 8, '.', digits, 'e2)'
    write(buf, fmt) x
    r = trim(adjustl(buf))
  end function sci

  !> one decimal and a leading zero: 0.1, 12.5, 3600.0
  function seconds(x) result(r)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: r
    r = fixed(x, 1)
  end function seconds

  !> x with digits decimals and a leading zero: 0.00, 11.60
  function fixed(x, digits) result(r)
    real(wp), intent(in) :: x
    integer, intent(in) :: digits
    character(len=:), allocatable :: r
    character(len=32) :: buf, fmt
    write(fmt, '(a,i0,a)') '(f24.', digits, ')'
    write(buf, fmt) x
    r = trim(adjustl(buf))
  end function fixed

  !> run.log's reason for the thermal effect
  function thermal_reason(s) result(text)
    type(sim_t), intent(in) :: s
    character(len=:), allocatable :: text
    if (s%ph%has_strength .and. s%cfg%thermal) then
      text = 'on: temperature from the EOS less elastic and stored work; Taylor-Quinney ' // &
        'heating; Johnson-Cook softening where the model has it'
    else if (s%ph%has_strength) then
      text = 'off: &physics thermal = .false. or no material needs it; the yield stress ' // &
        'sees the reference temperature'
    else
      text = 'off: no strength (a gas carries its temperature in e)'
    end if
  end function thermal_reason

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

  !> The facts of the run at its end. Collective. elapsed: the whole run's wall time, loop:
  !> the time loop's; base: this rank's resident memory before the grid (kB).
  function run_facts(s, elapsed, loop, base) result(f)
    type(sim_t), intent(inout) :: s
    real(wp), intent(in) :: elapsed, loop, base
    type(run_facts_t) :: f
    real(wp) :: work, cells
    integer :: k
    f%step = s%clk%step
    f%time = s%clk%time
    f%first_order_steps = s%diag%first_order_steps
    f%blocks_min = comm_min(size(s%blocks))
    f%blocks_max = comm_max(size(s%blocks))
    f%cell_steps = comm_sum(s%diag%cell_steps)
    f%fallback_faces = comm_sum(s%diag%fallback_faces)
    f%cells_low = comm_sum(s%diag%cells_low)
    f%gfm = gfm_count_list(s%gf%counts)
    do k = 1, size(f%gfm)
      f%gfm(k) = comm_sum(f%gfm(k))
    end do
    f%gfm_s = comm_max(timer_total(s%timers, 'gfm'))
    f%reinit_s = comm_max(timer_total(s%timers, 'reinit'))
    if (s%fix%on) then
      f%fixed = [sum(s%fix%taken(1, :)), sum(s%fix%taken(2, :))]
      ! the energy part off: its content is not tracked, no per cent to give; nor of a
      ! content of zero (solids at rest at their reference state hold no energy)
      f%fixed_percent = ieee_nan()
      if (abs(s%fix%content0(1)) > 0.0_wp) f%fixed_percent(1) = 100.0_wp * f%fixed(1) &
        / s%fix%content0(1)
      if (s%fix%energy .and. abs(s%fix%content0(2)) > 0.0_wp) f%fixed_percent(2) = 100.0_wp &
        * f%fixed(2) / s%fix%content0(2)
    end if
    f%fix_clamped = s%fix%clamped
    f%fix_aside = s%fix%aside
    f%wall = elapsed
    f%loop = loop
    f%fluxes = comm_max(timer_total(s%timers, 'fluxes'))
    f%halo = comm_max(timer_total(s%timers, 'halo'))
    f%dt = comm_max(timer_total(s%timers, 'dt'))
    f%output = comm_max(timer_total(s%timers, 'output'))
    ! work per rank: a rank with less waits for the others inside halo+bc
    work = timer_total(s%timers, 'fluxes') + timer_total(s%timers, 'gfm') + &
      timer_total(s%timers, 'reinit') + timer_total(s%timers, 'dt')
    f%work_min = comm_min(work)
    f%work_max = comm_max(work)
    cells = active_cells(s%lay)
    f%peak = 1024.0_wp * comm_sum(memory_kb('VmHWM'))
    f%peak_rank = 1024.0_wp * comm_max(memory_kb('VmHWM'))
    f%base = 1024.0_wp * comm_sum(base)
    f%per_cell = (f%peak - f%base) / cells
    f%arrays_per_cell = 8.0_wp * s%ph%nvar * (product(s%lay%bsize + 2 * s%lay%ng) &
      + 2 * product(s%lay%bsize)) / product(s%lay%bsize)
    f%halo_steps = s%plan%counts%steps
    ! (both plans: the flow exchange after the ghost fill may have its own, m_simulation)
    f%halo_exchanges = max_and_sum(s%plan%counts%exchanges + s%plan_flow%counts%exchanges)
    f%halo_messages = max_and_sum(s%plan%counts%messages + s%plan_flow%counts%messages)
    f%halo_bytes = max_and_sum(s%plan%counts%bytes + s%plan_flow%counts%bytes)
    f%halo_copy_bytes = max_and_sum(s%plan%counts%copy_bytes + s%plan_flow%counts%copy_bytes)

  contains

    !> the largest rank's count and the sum over the ranks (a count up to 2^53 as a real)
    function max_and_sum(n) result(both)
      integer(i8), intent(in) :: n
      integer(i8) :: both(2)
      both = [int(comm_max(real(n, wp)), i8), comm_sum(n)]
    end function max_and_sum

  end function run_facts

  !> run.log's line of the halo counts: per step of the largest rank, and over the run
  function halo_line(f) result(line)
    type(run_facts_t), intent(in) :: f
    character(len=line_len) :: line
    real(wp) :: steps
    steps = real(max(f%halo_steps, 1_i8), wp)
    write(line, '(5a,i0,3a,i0,3a)') 'halo: ', fixed(f%halo_messages(1) / steps, 2), &
      ' messages/step/rank (max), ', sci(f%halo_bytes(1) / steps, 3), &
      ' bytes/step/rank (max); total ', f%halo_messages(2), ' messages, ', &
      sci(real(f%halo_bytes(2), wp), 3), ' bytes over all ranks in ', f%halo_steps, &
      ' steps; local copies ', sci(f%halo_copy_bytes(1) / steps, 3), ' bytes/step/rank (max)'
  end function halo_line

  real(wp) function ieee_nan() result(x)
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    x = ieee_value(1.0_wp, ieee_quiet_nan)
  end function ieee_nan

  !> out_dir/run.json (manual/user-guide.md lists the keys): written by rank 0.
  subroutine run_json_write(s, f, path)
    type(sim_t), intent(in) :: s
    type(run_facts_t), intent(in) :: f
    character(len=*), intent(in) :: path
    type(json_t) :: js
    character(len=64) :: names(s%ph%nphase)
    integer :: k
    logical :: ok
    if (.not. comm_is_root()) return
    call json_begin(js)
    call json_put(js, 'format', 'sabre run 1')
    call json_put(js, 'status', 'complete')
    call json_put(js, 'title', s%cfg%title)
    call json_put(js, 'deck', s%cfg%deck_file)
    call json_put(js, 'out_dir', s%cfg%out_dir)
    call json_put(js, 'restart', s%cfg%restart)
    call json_object(js, 'build')
    call json_put(js, 'compiler', compiler_version())
    call json_put(js, 'flags', compiler_options())
    call json_close(js)
    call json_put(js, 'ranks', comm_size())
    call json_object(js, 'grid')
    call json_put(js, 'ndim', s%lay%ndim)
    call json_put_array(js, 'cells', s%lay%cells)
    call json_put_array(js, 'block', s%lay%bsize)
    call json_put(js, 'blocks', s%lay%nblocks)
    call json_put(js, 'active_blocks', count(s%lay%active))
    call json_put(js, 'blocks_per_rank_min', f%blocks_min)
    call json_put(js, 'blocks_per_rank_max', f%blocks_max)
    call json_put_array(js, 'block_rank', s%lay%owner)
    call json_close(js)
    call json_object(js, 'numerics')
    call json_put(js, 'scheme', s%cfg%scheme)
    call json_put(js, 'variables', s%cfg%variables)
    call json_put(js, 'flux', s%cfg%flux)
    call json_put(js, 'rk_order', s%cfg%rk_order)
    call json_put(js, 'cfl', s%cfg%cfl)
    call json_put(js, 'scalar_flux', s%cfg%scalar_flux)
    call json_put(js, 'surface_flux', s%cfg%surface_flux)
    call json_put(js, 'gfm_probe', s%cfg%gfm_probe)
    call json_put(js, 'conserve', s%cfg%conserve)
    call json_put(js, 'chosen', s%cfg%numerics_note)
    call json_close(js)
    do k = 1, s%ph%nphase
      names(k) = s%ph%material(k)
    end do
    call json_put_array(js, 'phases', names)
    call json_object(js, 'effects')
    call effect(js, 'strength', s%ph%has_strength, s%ph%strength_reason)
    call effect(js, 'thermal', s%ph%has_strength .and. s%cfg%thermal, thermal_reason(s))
    call effect(js, 'heat_conduction', s%ph%has_conduction, s%ph%conduction_reason)
    call effect(js, 'reaction', s%ph%has_reaction, s%ph%reaction_reason)
    call effect(js, 'interfaces', s%ls%n > 0, interfaces_reason(s))
    call effect(js, 'cut_cell_update', s%cut(1)%on, s%cut(1)%reason)
    if (s%ls%n > 0) then
      call effect(js, 'conservation_fix', s%fix%on, s%fix%reason)
    else
      call effect(js, 'conservation_fix', .false., 'off: no level sets')
    end if
    call json_close(js)
    call json_object(js, 'state')
    call json_put(js, 'variables', s%ph%nvar)
    call json_put(js, 'variables_per_phase', s%ph%nflow)
    call json_put(js, 'level_sets', s%ls%n)
    call json_close(js)
    call json_object(js, 'end')
    call json_put(js, 'step', f%step)
    call json_put(js, 'time', f%time)
    call json_close(js)
    call json_object(js, 'fallback')
    call json_put(js, 'faces', f%fallback_faces)
    call json_put(js, 'steps', f%first_order_steps)
    call json_put(js, 'cells', f%cells_low)
    call json_close(js)
    if (s%ls%n > 0) then
      call json_object(js, 'gfm')
      do k = 1, size(f%gfm)
        call json_put(js, trim(gfm_count_names(k)), f%gfm(k))
      end do
      call json_put(js, 'fill_seconds', f%gfm_s)
      call json_put(js, 'reinit_seconds', f%reinit_s)
      call json_close(js)
    end if
    if (s%fix%on) then
      call json_object(js, 'fix')
      call json_put(js, 'mass_kg', f%fixed(1))
      call json_put(js, 'mass_percent', f%fixed_percent(1))
      call json_put(js, 'energy', trim(merge('on ', 'off', s%fix%energy)))
      call json_put(js, 'energy_J', f%fixed(2))
      call json_put(js, 'energy_percent', f%fixed_percent(2))
      call json_put(js, 'clamped', f%fix_clamped)
      call json_put(js, 'aside_steps', f%fix_aside)
      call json_close(js)
    end if
    call hot_json(s%hot, js)
    call json_object(js, 'timings')
    call json_put_members(js, [character(len=16) :: 'wall_seconds', 'loop_seconds', &
      'fluxes_seconds', 'halo_seconds', 'dt_seconds', 'output_seconds', 'work_min_seconds', &
      'work_max_seconds'], [f%wall, f%loop, f%fluxes, f%halo, f%dt, f%output, f%work_min, &
      f%work_max])
    call json_close(js)
    call balance_json(js)
    call halo_json(js)
    call json_object(js, 'cost')
    call json_put(js, 'cell_steps', f%cell_steps)
    call json_put(js, 'cell_steps_per_second_per_rank', &
      real(f%cell_steps, wp) / max(f%wall, 1.0e-9_wp) / comm_size())
    call json_put(js, 'loop_cell_steps_per_second', &
      real(f%cell_steps, wp) / max(f%loop, 1.0e-9_wp))
    call json_close(js)
    call json_object(js, 'memory')
    call json_put(js, 'estimate_bytes_per_rank', sum(s%mem%parts))
    call json_object(js, 'estimate_parts')
    call json_put_members(js, mem_parts, s%mem%parts)
    call json_close(js)
    call json_put(js, 'baseline_bytes_rank0', s%mem%base)
    call json_put(js, 'node_available_bytes', s%mem%node_available)
    call json_put(js, 'node_ranks', s%mem%node_ranks)
    call json_put_members(js, [character(len=29) :: 'peak_resident_bytes', &
      'peak_resident_bytes_max_rank', 'baseline_bytes', 'bytes_per_cell_above_baseline', &
      'solver_array_bytes_per_cell'], [f%peak, f%peak_rank, f%base, f%per_cell, f%arrays_per_cell])
    call json_close(js)
    call json_end(js)
    call json_write(js, path, ok)
    if (.not. ok) call log_line('run.json: cannot write ' // trim(path))

  contains

    !> the load balance (m_rebalance): the setting, the imbalance at each check and each
    !> migration (step, blocks moved, imbalance measured before and predicted after, seconds)
    subroutine balance_json(jj)
      type(json_t), intent(inout) :: jj
      integer :: n, nm
      n = s%bal%nchecks
      nm = s%bal%nmoves
      call json_object(jj, 'balance')
      call json_put(jj, 'threshold', s%bal%threshold)
      call json_put(jj, 'every', s%bal%every)
      call json_put(jj, 'checks', n)
      if (n > 0) then
        call json_put(jj, 'imbalance_max', maxval(s%bal%checks(2, 1:n)))
        call json_put(jj, 'imbalance_mean', sum(s%bal%checks(2, 1:n)) / n)
        call json_put(jj, 'imbalance_last', s%bal%checks(2, n))
        call json_put_array(jj, 'check_steps', nint(s%bal%checks(1, 1:n)))
        call json_put_array(jj, 'imbalance', s%bal%checks(2, 1:n))
        ! the critical path of the stage work (sum over checks of the largest rank's) and
        ! its ideal (of the mean), processor seconds; the imbalance of the wall times
        call json_put(jj, 'work_max_seconds', sum(s%bal%checks(3, 1:n)))
        call json_put(jj, 'work_mean_seconds', sum(s%bal%checks(4, 1:n)))
        call json_put_array(jj, 'imbalance_wall', s%bal%checks(5, 1:n))
        ! the ranks' own work of every kind (processor time less waits: m_balance)
        call json_put_array(jj, 'imbalance_all', s%bal%checks(6, 1:n))
      end if
      call json_put(jj, 'migrations', nm)
      if (nm > 0) then
        call json_put_array(jj, 'migration_steps', nint(s%bal%moves(1, 1:nm)))
        call json_put_array(jj, 'migration_blocks', nint(s%bal%moves(2, 1:nm)))
        call json_put_array(jj, 'migration_before', s%bal%moves(3, 1:nm))
        call json_put_array(jj, 'migration_predicted', s%bal%moves(4, 1:nm))
        call json_put_array(jj, 'migration_seconds', s%bal%moves(5, 1:nm))
      end if
      call json_close(jj)
    end subroutine balance_json

    !> the halo counts of the time loop: per step of the largest rank, and the totals
    subroutine halo_json(jj)
      type(json_t), intent(inout) :: jj
      real(wp) :: steps
      steps = real(max(f%halo_steps, 1_i8), wp)
      call json_object(jj, 'halo')
      call json_put(jj, 'steps', f%halo_steps)
      call json_put(jj, 'exchanges_per_step', f%halo_exchanges(1) / steps)
      call json_put(jj, 'messages_per_step_max_rank', f%halo_messages(1) / steps)
      call json_put(jj, 'bytes_per_step_max_rank', f%halo_bytes(1) / steps)
      call json_put(jj, 'copy_bytes_per_step_max_rank', f%halo_copy_bytes(1) / steps)
      call json_put(jj, 'messages_max_rank', f%halo_messages(1))
      call json_put(jj, 'messages_all_ranks', f%halo_messages(2))
      call json_put(jj, 'bytes_max_rank', f%halo_bytes(1))
      call json_put(jj, 'bytes_all_ranks', f%halo_bytes(2))
      call json_put(jj, 'copy_bytes_max_rank', f%halo_copy_bytes(1))
      call json_put(jj, 'copy_bytes_all_ranks', f%halo_copy_bytes(2))
      call json_close(jj)
    end subroutine halo_json

    subroutine effect(jj, key, on, why)
      type(json_t), intent(inout) :: jj
      character(len=*), intent(in) :: key, why
      logical, intent(in) :: on
      call json_object(jj, key)
      call json_put(jj, 'on', on)
      call json_put(jj, 'why', adjustl(why))
      call json_close(jj)
    end subroutine effect

  end subroutine run_json_write

end module m_run_report
