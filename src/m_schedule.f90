!> The time loop's output schedule (DESIGN section 7): the history rows (every history_every
!> steps, in m_history), the plot files (every plot_dt of simulated time or every plot_every
!> steps, m_output), the checkpoints (every checkpoint_every steps, m_checkpoint), and the
!> stop before the end: at the wall-clock limit or on a batch queue's signal (m_signals), with
!> a checkpoint to continue from. The loop (m_timeloop) says when a step is done; this says
!> what is written then. It chooses no step size and writes no field itself.
module m_schedule
  use m_kinds, only: wp, line_len
  use m_simulation, only: sim_t
  use m_output, only: output_plot, history_columns, history_values, step_file_name
  use m_checkpoint, only: output_checkpoint
  use m_history, only: history_t, history_open, history_write, history_close
  use m_comm, only: comm_max, comm_wtime, comm_bcast, comm_is_root
  use m_errors, only: log_line
  use m_signals, only: signal_caught, signal_name
  use m_timers, only: timer_start, timer_stop
  implicit none
  private
  public :: schedule_t, schedule_open, output_due, stop_now, schedule_close

  !> the history file, and the wall-clock time of the slowest step (for the stop's margin)
  type, public :: schedule_t
    type(history_t) :: hist
    real(wp) :: worst_step = 0.0_wp
  end type schedule_t

contains

  !> The history file (continued from restart_step after a restart, or -1); on a fresh run the
  !> plot file and the history row of the initial state.
  subroutine schedule_open(sim, sch, restart_step)
    type(sim_t), intent(inout) :: sim
    type(schedule_t), intent(out) :: sch
    integer, intent(in) :: restart_step
    call history_open(sch%hist, trim(sim%cfg%out_dir) // '/history.csv', &
      history_columns(sim), restart_step)
    if (restart_step < 0) then
      if (sim%cfg%plot_dt > 0.0_wp .or. sim%cfg%plot_every > 0) call output_plot(sim)
      if (sim%cfg%plot_dt > 0.0_wp) sim%clk%next_plot_time = sim%cfg%plot_dt
      call history_write(sch%hist, sim%clk%step, history_values(sim))
    end if
  end subroutine schedule_open

  !> history row, plot file and checkpoint when the schedule says so
  subroutine output_due(sim, sch, deck_text)
    type(sim_t), intent(inout) :: sim
    type(schedule_t), intent(inout) :: sch
    character(len=*), intent(in) :: deck_text
    call timer_start(sim%timers, 'output')
    if (mod(sim%clk%step, max(sim%cfg%history_every, 1)) == 0) &
      call history_write(sch%hist, sim%clk%step, history_values(sim))
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
  logical function stop_now(sim, sch, deck_text) result(stop)
    type(sim_t), intent(inout) :: sim
    type(schedule_t), intent(in) :: sch
    character(len=*), intent(in) :: deck_text
    logical :: stop_wall
    integer :: signum
    character(len=line_len) :: msg
    stop_wall = .false.
    if (sim%cfg%wall_limit > 0.0_wp .and. comm_is_root()) stop_wall = &
      comm_wtime() - sim%clk%wall_start + 3.0_wp * sch%worst_step + 5.0_wp > sim%cfg%wall_limit
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

  !> At the loop's end: the last history row (unless the schedule just wrote it), the history
  !> file closed, the last plot file.
  subroutine schedule_close(sim, sch)
    type(sim_t), intent(inout) :: sim
    type(schedule_t), intent(inout) :: sch
    if (mod(sim%clk%step, max(sim%cfg%history_every, 1)) /= 0) &
      call history_write(sch%hist, sim%clk%step, history_values(sim))
    call history_close(sch%hist)
    call output_plot(sim)
  end subroutine schedule_close

end module m_schedule
