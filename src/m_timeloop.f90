!> The time loop (DESIGN section 5): the step size (CFL, as a max of signal rates over the
!> ranks), the step (m_step) with the step fallback when it leaves a cell inadmissible
!> (m_fallback), the level sets' reinitialisation (m_levelset_reinit) and the conservation
!> fix (m_gfm_conserve), then history, plot files, checkpoints, the load balance check
!> (m_rebalance), the progress line and the stop at the wall-clock limit or a batch queue's
!> signal.
module m_timeloop
  use m_kinds, only: wp, i8, line_len
  use m_simulation, only: sim_t, sim_rate
  use m_step, only: advance
  use m_euler, only: numerics_t
  use m_fallback, only: fallback_step, fallback_numerics
  use m_levelset_bodies, only: ls_material, ls_void
  use m_levelset_reinit, only: levelset_reinitialise
  use m_gfm_conserve, only: conserve_fix
  use m_output, only: output_plot, history_columns, history_values, step_file_name
  use m_checkpoint, only: output_checkpoint
  use m_history, only: history_t, history_open, history_write, history_close
  use m_config, only: is_set
  use m_comm, only: comm_max, comm_wtime, comm_bcast, comm_is_root
  use m_errors, only: stop_collective, log_line
  use m_signals, only: signal_caught, signal_name
  use m_timers, only: timer_start, timer_stop
  use m_run_report, only: progress_t, progress_start, progress_report
  use m_rebalance, only: rebalance_check
  use m_halo, only: halo_counts_t
  implicit none
  private
  public :: run_time_loop

contains

  !> stopped: the run stopped before its end (wall_limit or a caught signal) after writing a
  !> checkpoint to continue from.
  subroutine run_time_loop(sim, deck_text, stopped)
    type(sim_t), intent(inout) :: sim
    character(len=*), intent(in) :: deck_text
    logical, intent(out) :: stopped
    type(history_t) :: hist
    type(progress_t) :: progress
    real(wp) :: rate, t_end, t0, worst_step
    logical :: ok, stop_bad, changed, moves(sim%ls%n)
    integer :: restart_step, b
    stopped = .false.
    t_end = huge(1.0_wp)
    if (is_set(sim%cfg%t_end)) t_end = sim%cfg%t_end
    restart_step = -1
    if (len_trim(sim%cfg%restart) > 0) restart_step = sim%clk%step
    ! the level sets that reinitialisation rebuilds: those of material and void bodies
    moves = sim%ls%kind == ls_material .or. sim%ls%kind == ls_void
    if (sim%fix%on .and. restart_step < 0) then
      call conserve(.false.)
      sim%fix%content0 = sum(sim%fix%content, dim=2)
    end if
    call history_open(hist, trim(sim%cfg%out_dir) // '/history.csv', history_columns(sim), &
      restart_step)
    if (restart_step < 0) then
      if (sim%cfg%plot_dt > 0.0_wp .or. sim%cfg%plot_every > 0) call output_plot(sim)
      if (sim%cfg%plot_dt > 0.0_wp) sim%clk%next_plot_time = sim%cfg%plot_dt
      call history_write(hist, sim%clk%step, history_values(sim))
    end if
    worst_step = 0.0_wp
    call progress_start(sim, progress)
    ! the halo counts of run.json are the loop's: per step, without the set-up's exchanges
    sim%plan%counts = halo_counts_t()
    call sim_rate(sim, rate, ok)
    stop_bad = .not. ok
    do
      if (stop_bad .or. at_end()) exit
      call choose_dt(rate)
      t0 = comm_wtime()
      call advance(sim)
      call timer_start(sim%timers, 'dt')
      ok = .false.
      if (.not. sim%diag%step_failed) call sim_rate(sim, rate, ok)
      call timer_stop(sim%timers, 'dt')
      if (.not. ok) then
        call fallback_step(sim, sim%clk%step + 1, sim%clk%dt, &
          sim%diag%first_order_steps + 1, redo_first_order, ok)
        sim%diag%first_order_steps = sim%diag%first_order_steps + 1
        if (ok) call sim_rate(sim, rate, ok)
      end if
      stop_bad = .not. ok
      if (mod(sim%clk%step + 1, sim%cfg%reinit_every) == 0 .and. any(moves)) then
        call timer_start(sim%timers, 'reinit')
        call levelset_reinitialise(sim%plan, sim%lay, sim%bc, sim%ph, sim%blocks, moves, &
          sim%cfg%band, sim%clk%time, sim%gf%dormant)
        call timer_stop(sim%timers, 'reinit')
      end if
      if (sim%fix%on .and. ok) then
        call timer_start(sim%timers, 'gfm')
        call conserve(.true., changed)
        call timer_stop(sim%timers, 'gfm')
        ! the next step's size from the fixed state (as a restart from here would have it)
        if (changed) call sim_rate(sim, rate, ok)
        stop_bad = .not. ok
      end if
      sim%clk%time = sim%clk%time + sim%clk%dt
      sim%clk%step = sim%clk%step + 1
      sim%plan%counts%steps = sim%plan%counts%steps + 1
      sim%diag%cell_steps = sim%diag%cell_steps + sum([(int(product(sim%blocks(b)%n), i8), &
        b = 1, size(sim%blocks))])
      worst_step = max(worst_step, comm_wtime() - t0)
      call output_due()
      ! blocks to other ranks when the work has drifted (results unchanged: m_rebalance)
      call rebalance_check(sim)
      call progress_report(sim, progress, t_end, .false.)
      ! a run at its end has nothing to continue: it ends as a complete run
      if (at_end()) cycle
      if (stop_now()) then
        stopped = .true.
        exit
      end if
    end do
    if (mod(sim%clk%step, max(sim%cfg%history_every, 1)) /= 0) &
      call history_write(hist, sim%clk%step, history_values(sim))
    call history_close(hist)
    call output_plot(sim)
    call progress_report(sim, progress, t_end, .true.)
    call stop_collective('ERROR [time loop]: ' // inadmissible() // '; the last plot file ' &
      // 'shows it; lower cfl or use a more dissipative scheme (eno1/eno2, llf)', .not. stop_bad)

  contains

    logical function at_end()
      at_end = sim%clk%time >= t_end * (1.0_wp - 1.0e-12_wp) &
        .or. sim%clk%step >= sim%cfg%max_steps
    end function at_end

    !> dt from the CFL number, held to dt_max, the next plot time and the end time
    subroutine choose_dt(r)
      real(wp), intent(in) :: r
      sim%clk%dt = sim%cfg%cfl / r
      if (is_set(sim%cfg%dt_max)) sim%clk%dt = min(sim%clk%dt, sim%cfg%dt_max)
      if (sim%clk%step == 0) sim%clk%dt_first = sim%clk%dt
      if (sim%cfg%plot_dt > 0.0_wp .and. sim%clk%time + sim%clk%dt > sim%clk%next_plot_time) &
        sim%clk%dt = max(sim%clk%next_plot_time - sim%clk%time, 0.0_wp)
      if (sim%clk%time + sim%clk%dt > t_end) sim%clk%dt = t_end - sim%clk%time
    end subroutine choose_dt

    !> history row, plot file and checkpoint when the schedule says so
    subroutine output_due()
      call timer_start(sim%timers, 'output')
      if (mod(sim%clk%step, max(sim%cfg%history_every, 1)) == 0) &
        call history_write(hist, sim%clk%step, history_values(sim))
      if (sim%cfg%plot_dt > 0.0_wp .and. &
        sim%clk%time >= sim%clk%next_plot_time * (1 - 1e-12_wp)) then
        call output_plot(sim)
        sim%clk%next_plot_time = sim%clk%next_plot_time + sim%cfg%plot_dt
      else if (sim%cfg%plot_every > 0) then
        if (mod(sim%clk%step, sim%cfg%plot_every) == 0) call output_plot(sim)
      end if
      if (sim%cfg%checkpoint_every > 0) then
        if (mod(sim%clk%step, sim%cfg%checkpoint_every) == 0) &
          call output_checkpoint(sim, deck_text)
      end if
      call timer_stop(sim%timers, 'output')
    end subroutine output_due

    !> the wall-clock limit near (3 of the slowest steps and 5 s to spare), or a batch
    !> queue's warning or time-limit signal on any rank (m_signals): a checkpoint, and why
    logical function stop_now() result(stop)
      logical :: stop_wall
      integer :: signum
      character(len=line_len) :: msg
      stop_wall = .false.
      if (sim%cfg%wall_limit > 0.0_wp .and. comm_is_root()) stop_wall = &
        comm_wtime() - sim%clk%wall_start + 3.0_wp * worst_step + 5.0_wp > sim%cfg%wall_limit
      call comm_bcast(stop_wall, 0)
      signum = comm_max(signal_caught())
      stop = stop_wall .or. signum > 0
      if (.not. stop) return
      call output_checkpoint(sim, deck_text)
      write(msg, '(a,i0,a)') 'stopped cleanly at step ', sim%clk%step, &
        '; continue with &run restart = ''' // &
        trim(step_file_name(sim, 'chk', sim%clk%step, '.h5')) // ''''
      if (stop_wall) then
        call log_line('wall_limit: ' // msg)
      else
        call log_line(trim(signal_name(signum)) // ' caught: ' // msg)
      end if
    end function stop_now

    function inadmissible() result(msg)
      character(len=line_len) :: msg
      write(msg, '(a,i0,a,es12.5)') 'inadmissible state (rho <= 0, c^2 <= 0 or NaN) at ' // &
        'step ', sim%clk%step, ', time ', sim%clk%time
    end function inadmissible

    subroutine conserve(apply, chg)
      logical, intent(in) :: apply
      logical, intent(out), optional :: chg
      call conserve_fix(sim%fix, sim%lay, sim%bc, sim%ls, sim%ph, sim%gf, sim%blocks, &
        sim%cfg%rk_order, sim%clk%dt, apply, chg)
    end subroutine conserve

  end subroutine run_time_loop

  !> The step fallback's redo (m_fallback): the state back to the step's start, the step
  !> again with dt at first order in space.
  subroutine redo_first_order(ctx, dt, ok)
    class(*), intent(inout) :: ctx
    real(wp), intent(in) :: dt
    logical, intent(out) :: ok
    type(numerics_t) :: keep
    real(wp) :: rate
    integer :: b
    ok = .false.
    select type (sim => ctx)
    type is (sim_t)
      sim%clk%dt = dt
      do b = 1, size(sim%blocks)
        associate (q => sim%blocks(b)%q, n => sim%blocks(b)%n)
          q(1:n(1), 1:n(2), 1:n(3), :) = sim%blocks(b)%q0
        end associate
      end do
      keep = sim%num
      sim%num = fallback_numerics(keep)
      call advance(sim)
      sim%num = keep
      if (.not. sim%diag%step_failed) call sim_rate(sim, rate, ok)
    end select
  end subroutine redo_first_order

end module m_timeloop
