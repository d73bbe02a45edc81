!> The time loop (DESIGN section 5), as a recipe: the step size (CFL, as a max of signal rates
!> over the ranks), the step (m_step), the step fallback when it leaves a cell inadmissible
!> and the corrections (m_step_after), the output schedule (m_schedule), the load balance
!> check (m_rebalance), the progress line, and the stop at the end, at the wall-clock limit
!> or on a batch queue's signal (m_schedule).
module m_timeloop
  use m_kinds, only: wp, i8, line_len
  use m_simulation, only: sim_t, sim_rate
  use m_step, only: advance
  use m_step_after, only: step_fallback, step_corrections, conserve_start
  use m_schedule, only: schedule_t, schedule_open, output_due, stop_now, schedule_close
  use m_config, only: is_set
  use m_comm, only: comm_wtime
  use m_errors, only: stop_collective
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
    type(schedule_t) :: sch
    type(progress_t) :: progress
    real(wp) :: rate, t_end, t0
    logical :: ok, stop_bad
    integer :: restart_step, b
    stopped = .false.
    t_end = huge(1.0_wp)
    if (is_set(sim%cfg%t_end)) t_end = sim%cfg%t_end
    restart_step = -1
    if (len_trim(sim%cfg%restart) > 0) restart_step = sim%clk%step
    if (restart_step < 0) call conserve_start(sim)
    call schedule_open(sim, sch, restart_step)
    call progress_start(sim, progress)
    ! the halo counts of run.json are the loop's: per step, without the set-up's exchanges
    sim%plan%counts = halo_counts_t()
    sim%plan_flow%counts = halo_counts_t()
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
      if (.not. ok) call step_fallback(sim, rate, ok)
      call step_corrections(sim, rate, ok)
      stop_bad = .not. ok
      sim%clk%time = sim%clk%time + sim%clk%dt
      sim%clk%step = sim%clk%step + 1
      sim%plan%counts%steps = sim%plan%counts%steps + 1
      sim%diag%cell_steps = sim%diag%cell_steps + sum([(int(product(sim%blocks(b)%n), i8), &
        b = 1, size(sim%blocks))])
      sch%worst_step = max(sch%worst_step, comm_wtime() - t0)
      call output_due(sim, sch, deck_text)
      ! blocks to other ranks when the work has drifted (results unchanged: m_rebalance)
      call rebalance_check(sim)
      call progress_report(sim, progress, t_end, .false.)
      ! a run at its end has nothing to continue: it ends as a complete run
      if (at_end()) cycle
      if (stop_now(sim, sch, deck_text)) then
        stopped = .true.
        exit
      end if
    end do
    call schedule_close(sim, sch)
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

    function inadmissible() result(msg)
      character(len=line_len) :: msg
      write(msg, '(a,i0,a,es12.5)') 'inadmissible state (rho <= 0, c^2 <= 0 or NaN) at ' // &
        'step ', sim%clk%step, ', time ', sim%clk%time
    end function inadmissible

  end subroutine run_time_loop

end module m_timeloop
