!> The time loop (DESIGN section 5): CFL step as a min over ranks, TVD Runge-Kutta stages of
!> halo exchange, boundary conditions, right-hand side and stage update, then history, plot
!> files, checkpoints and the wall-clock limit. The only place that strings a step together.
module m_timeloop
  use m_kinds, only: wp, i8, line_len
  use m_simulation, only: sim_t
  use m_halo, only: halo_exchange
  use m_boundary, only: boundary_apply, boundary_walls
  use m_euler, only: euler_rhs, euler_max_rate, rk_stage_update, plastic_correction
  use m_reconstruct, only: scheme_eno1
  use m_flux, only: flux_kind_llf
  use m_output, only: output_plot, output_checkpoint, history_columns, history_values, &
    step_file_name
  use m_history, only: history_t, history_open, history_write, history_close
  use m_config, only: is_set
  use m_comm, only: comm_max, comm_any, comm_sum, comm_wtime, comm_bcast, comm_is_root
  use m_errors, only: stop_collective, log_line
  use m_timers, only: timer_start, timer_stop
  implicit none
  private
  public :: run_time_loop

contains

  subroutine run_time_loop(sim, deck_text)
    type(sim_t), intent(inout) :: sim
    character(len=*), intent(in) :: deck_text
    type(history_t) :: hist
    real(wp) :: rate, t_end, step_wall, t0, worst_step
    logical :: ok, stop_wall, stop_bad
    character(len=line_len) :: msg
    integer :: restart_step
    t_end = huge(1.0_wp)
    if (is_set(sim%cfg%t_end)) t_end = sim%cfg%t_end
    restart_step = -1
    if (len_trim(sim%cfg%restart) > 0) restart_step = sim%step
    call history_open(hist, trim(sim%cfg%out_dir) // '/history.csv', history_columns(), &
      restart_step)
    if (restart_step < 0) then
      if (sim%cfg%plot_dt > 0.0_wp .or. sim%cfg%plot_every > 0) call output_plot(sim)
      if (sim%cfg%plot_dt > 0.0_wp) sim%next_plot_time = sim%cfg%plot_dt
      call history_write(hist, sim%step, history_values(sim))
    end if
    worst_step = 0.0_wp
    call step_size(sim, rate, ok)
    stop_bad = .not. ok
    do
      if (stop_bad) exit
      if (sim%time >= t_end * (1.0_wp - 1.0e-12_wp) .or. sim%step >= sim%cfg%max_steps) exit
      sim%dt = sim%cfg%cfl / rate
      if (is_set(sim%cfg%dt_max)) sim%dt = min(sim%dt, sim%cfg%dt_max)
      if (sim%step == 0) sim%dt_first = sim%dt
      if (sim%cfg%plot_dt > 0.0_wp .and. sim%time + sim%dt > sim%next_plot_time) &
        sim%dt = max(sim%next_plot_time - sim%time, 0.0_wp)
      if (sim%time + sim%dt > t_end) sim%dt = t_end - sim%time
      t0 = comm_wtime()
      call advance(sim)
      call timer_start(sim%timers, 'dt')
      ok = .false.
      if (.not. sim%step_failed) call step_size(sim, rate, ok)
      call timer_stop(sim%timers, 'dt')
      if (.not. ok) call recompute_first_order(sim, rate, ok)
      stop_bad = .not. ok
      sim%time = sim%time + sim%dt
      sim%step = sim%step + 1
      sim%cell_steps = sim%cell_steps + int(size(sim%blocks), i8) * product(sim%lay%bsize)
      step_wall = comm_wtime() - t0
      worst_step = max(worst_step, step_wall)
      call timer_start(sim%timers, 'output')
      if (mod(sim%step, max(sim%cfg%history_every, 1)) == 0) &
        call history_write(hist, sim%step, history_values(sim))
      if (sim%cfg%plot_dt > 0.0_wp .and. sim%time >= sim%next_plot_time * (1 - 1e-12_wp)) then
        call output_plot(sim)
        sim%next_plot_time = sim%next_plot_time + sim%cfg%plot_dt
      else if (sim%cfg%plot_every > 0) then
        if (mod(sim%step, sim%cfg%plot_every) == 0) call output_plot(sim)
      end if
      if (sim%cfg%checkpoint_every > 0) then
        if (mod(sim%step, sim%cfg%checkpoint_every) == 0) call output_checkpoint(sim, deck_text)
      end if
      call timer_stop(sim%timers, 'output')
      stop_wall = .false.
      if (sim%cfg%wall_limit > 0.0_wp .and. comm_is_root()) stop_wall = &
        comm_wtime() - sim%wall_start + 3.0_wp * worst_step + 5.0_wp > sim%cfg%wall_limit
      call comm_bcast(stop_wall, 0)
      if (stop_wall) then
        call output_checkpoint(sim, deck_text)
        write(msg, '(a,i0,a)') 'wall_limit: stopped cleanly at step ', sim%step, &
          '; continue with &run restart = ''' // &
          trim(step_file_name(sim, 'chk', sim%step, '.h5')) // ''''
        call log_line(msg)
        exit
      end if
    end do
    if (mod(sim%step, max(sim%cfg%history_every, 1)) /= 0) &
      call history_write(hist, sim%step, history_values(sim))
    call history_close(hist)
    call output_plot(sim)
    write(msg, '(a,i0,a,es12.5)') 'inadmissible state (rho <= 0, c^2 <= 0 or NaN) at step ', &
      sim%step, ', time ', sim%time
    call stop_collective('ERROR [time loop]: ' // trim(msg) // '; the last plot file ' // &
      'shows it; lower cfl or use a more dissipative scheme (eno1/eno2, llf)', .not. stop_bad)
  end subroutine run_time_loop

  !> The a-posteriori fallback (manual/theory.md section 3): when a step leaves any cell
  !> inadmissible on any rank, the whole step is recomputed from its start at first order in
  !> space (eno1 + LLF, same Runge-Kutta), and if that is still inadmissible, with dt halved,
  !> up to four times. Every rank takes the same decision, so results stay bit-identical on
  !> any number of ranks; run.log and history.csv (first_order_steps) say how often it was
  !> needed. Nothing is clipped.
  subroutine recompute_first_order(sim, rate, ok)
    type(sim_t), intent(inout) :: sim
    real(wp), intent(out) :: rate
    logical, intent(out) :: ok
    integer :: scheme, flux, halvings, b
    character(len=line_len) :: msg
    scheme = sim%scheme
    flux = sim%flux
    sim%scheme = scheme_eno1
    sim%flux = flux_kind_llf
    ok = .false.
    do halvings = 0, 4
      if (halvings > 0) sim%dt = 0.5_wp * sim%dt
      do b = 1, size(sim%blocks)
        associate (q => sim%blocks(b)%q, n => sim%lay%bsize)
          q(1:n(1), 1:n(2), 1:n(3), :) = sim%blocks(b)%q0
        end associate
      end do
      call advance(sim)
      ok = .false.
      if (.not. sim%step_failed) call step_size(sim, rate, ok)
      if (ok) exit
    end do
    sim%scheme = scheme
    sim%flux = flux
    sim%first_order_steps = sim%first_order_steps + 1
    if (sim%first_order_steps <= 10) then
      write(msg, '(a,i0,a,i0,a)') 'fallback: step ', sim%step + 1, &
        ' recomputed at first order in space (eno1 + llf), dt halved ', halvings, ' times'
      if (.not. ok) msg = trim(msg) // ': still inadmissible'
      call log_line(msg)
    end if
  end subroutine recompute_first_order

  !> Global signal rate (max over ranks) and admissibility of every cell.
  subroutine step_size(sim, rate, ok)
    type(sim_t), intent(inout) :: sim
    real(wp), intent(out) :: rate
    logical, intent(out) :: ok
    real(wp) :: r
    logical :: good, all_good
    integer :: b
    rate = 0.0_wp
    all_good = .true.
    do b = 1, size(sim%blocks)
      call euler_max_rate(sim%lay, sim%eos, sim%shear, sim%blocks(b)%q, r, good)
      rate = max(rate, r)
      all_good = all_good .and. good
    end do
    ok = .not. comm_any(.not. all_good)
    rate = comm_max(rate)
    if (.not. rate > 0.0_wp) rate = tiny(1.0_wp)
  end subroutine step_size

  !> One time step of sim%dt by TVD Runge-Kutta of order rk_order.
  subroutine advance(sim)
    type(sim_t), intent(inout) :: sim
    integer :: stage, b
    integer(i8) :: nfall
    real(wp) :: tstage, vwall(2, 3)
    logical :: wall(2, 3)
    real(wp), parameter :: stage_time(3, 3) = reshape([0.0_wp, 0.0_wp, 0.0_wp, &
      0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.5_wp], [3, 3])
    integer :: nf
    logical :: failed
    nf = 0
    failed = .false.
    sim%step_failed = .false.
    do stage = 1, sim%cfg%rk_order
      tstage = sim%time + stage_time(stage, sim%cfg%rk_order) * sim%dt
      call timer_start(sim%timers, 'halo')
      call halo_exchange(sim%plan, sim%blocks, sim%nvar)
      call boundary_apply(sim%lay, sim%bc, sim%blocks, sim%nvar, tstage)
      call timer_stop(sim%timers, 'halo')
      call timer_start(sim%timers, 'fluxes')
      do b = 1, size(sim%blocks)
        call boundary_walls(sim%lay, sim%bc, sim%blocks(b), tstage, wall, vwall)
        call euler_rhs(sim%lay, sim%eos, sim%st, sim%scheme, sim%flux, sim%blocks(b)%q, &
          sim%blocks(b)%rhs, sim%blocks(b)%offset, wall, vwall, sim%work, nf, failed)
        if (failed) exit
        call rk_stage_update(sim%lay, stage, sim%cfg%rk_order, sim%dt, sim%blocks(b)%q, &
          sim%blocks(b)%q0, sim%blocks(b)%rhs)
        if (sim%has_strength) call plastic_correction(sim%lay, sim%eos, sim%st, &
          sim%cfg%thermal, sim%dt, sim%blocks(b)%q)
      end do
      call timer_stop(sim%timers, 'fluxes')
      ! a stage whose state has no admissible cell values somewhere ends the step on every
      ! rank: the caller recomputes it at first order
      sim%step_failed = comm_any(failed)
      if (sim%step_failed) exit
    end do
    nfall = int(nf, i8)
    sim%fallback_faces = sim%fallback_faces + nfall
    sim%fallback_step = comm_sum(nfall)
  end subroutine advance

end module m_timeloop
