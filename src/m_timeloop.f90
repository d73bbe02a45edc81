!> The time loop (DESIGN section 5): CFL step as a min over ranks, TVD Runge-Kutta stages of
!> halo exchange, boundary conditions, right-hand side and stage update, then history, plot
!> files, checkpoints and the wall-clock limit. The only place that strings a step together.
module m_timeloop
  use m_kinds, only: wp, i8, line_len
  use m_simulation, only: sim_t, sim_block_work
  use m_halo, only: halo_exchange, halo_refresh
  use m_boundary, only: boundary_apply, boundary_walls, bc_outflow
  use m_euler, only: euler_rhs, euler_max_rate, rk_stage_update, plastic_correction, &
    primitive_row, rk_weights
  use m_eos, only: eos_sound_speed2
  use m_reconstruct, only: scheme_eno1
  use m_flux, only: flux_kind_llf
  use m_output, only: output_plot, output_checkpoint, history_columns, history_values, &
    step_file_name
  use m_history, only: history_t, history_open, history_write, history_close
  use m_config, only: is_set
  use m_comm, only: comm_max, comm_any, comm_sum, comm_wtime, comm_bcast, comm_is_root, &
    comm_sum_array
  use m_errors, only: stop_collective, log_line
  use m_signals, only: signal_caught, signal_name
  use m_timers, only: timer_start, timer_stop
  use m_gfm, only: gfm_fill, gfm_rest, gfm_drop_debris, gfm_dormant
  use m_gfm_conserve, only: n_content, content_block, fix_block
  use m_levelset_bodies, only: ls_rigid, ls_material, ls_void, ls_separate, ls_region
  use m_levelset_advect, only: levelset_advect_rhs
  use m_levelset_reinit, only: levelset_reinit_step
  use m_scene, only: body_distance, cell_centre
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en
  use m_run_report, only: progress_t, progress_start, progress_report
  implicit none
  private
  public :: run_time_loop

  !> The level sets of one block with its halo (blocks may differ in extent, m_layout).
  type :: level_sets_t
    real(wp), allocatable :: phi(:, :, :, :)
  end type level_sets_t

contains

  !> stopped: the run stopped before its end (wall_limit or a caught signal) after writing a
  !> checkpoint to continue from.
  subroutine run_time_loop(sim, deck_text, stopped)
    type(sim_t), intent(inout) :: sim
    character(len=*), intent(in) :: deck_text
    logical, intent(out) :: stopped
    type(history_t) :: hist
    type(progress_t) :: progress
    real(wp) :: rate, t_end, step_wall, t0, worst_step
    logical :: ok, stop_wall, stop_bad, changed
    character(len=line_len) :: msg
    integer :: restart_step, b, signum
    stopped = .false.
    t_end = huge(1.0_wp)
    if (is_set(sim%cfg%t_end)) t_end = sim%cfg%t_end
    restart_step = -1
    if (len_trim(sim%cfg%restart) > 0) restart_step = sim%step
    if (sim%fix_mass .and. restart_step < 0) then
      call conserve_step(sim, .false.)
      sim%content0 = sum(sim%content, dim=2)
    end if
    call history_open(hist, trim(sim%cfg%out_dir) // '/history.csv', history_columns(sim), &
      restart_step)
    if (restart_step < 0) then
      if (sim%cfg%plot_dt > 0.0_wp .or. sim%cfg%plot_every > 0) call output_plot(sim)
      if (sim%cfg%plot_dt > 0.0_wp) sim%next_plot_time = sim%cfg%plot_dt
      call history_write(hist, sim%step, history_values(sim))
    end if
    worst_step = 0.0_wp
    call progress_start(sim, progress)
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
      if (sim%ls%n > 0 .and. mod(sim%step + 1, sim%cfg%reinit_every) == 0) &
        call reinitialise(sim)
      if (sim%fix_mass .and. ok) then
        call timer_start(sim%timers, 'gfm')
        call conserve_step(sim, .true., changed)
        call timer_stop(sim%timers, 'gfm')
        ! the next step's size from the fixed state (as a restart from here would have it)
        if (changed) call step_size(sim, rate, ok)
        stop_bad = .not. ok
      end if
      sim%time = sim%time + sim%dt
      sim%step = sim%step + 1
      sim%cell_steps = sim%cell_steps + sum([(int(product(sim%blocks(b)%n), i8), &
        b = 1, size(sim%blocks))])
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
      call progress_report(sim, progress, t_end, .false.)
      stop_wall = .false.
      if (sim%cfg%wall_limit > 0.0_wp .and. comm_is_root()) stop_wall = &
        comm_wtime() - sim%wall_start + 3.0_wp * worst_step + 5.0_wp > sim%cfg%wall_limit
      call comm_bcast(stop_wall, 0)
      ! a batch queue's warning or time-limit signal, on any rank (m_signals)
      signum = comm_max(signal_caught())
      ! a run at its end has nothing to continue: it ends as a complete run
      if (sim%time >= t_end * (1.0_wp - 1.0e-12_wp) .or. sim%step >= sim%cfg%max_steps) &
        cycle
      if (stop_wall .or. signum > 0) then
        call output_checkpoint(sim, deck_text)
        write(msg, '(a,i0,a)') 'stopped cleanly at step ', sim%step, &
          '; continue with &run restart = ''' // &
          trim(step_file_name(sim, 'chk', sim%step, '.h5')) // ''''
        if (stop_wall) then
          call log_line('wall_limit: ' // msg)
        else
          call log_line(trim(signal_name(signum)) // ' caught: ' // msg)
        end if
        stopped = .true.
        exit
      end if
    end do
    if (mod(sim%step, max(sim%cfg%history_every, 1)) /= 0) &
      call history_write(hist, sim%step, history_values(sim))
    call history_close(hist)
    call output_plot(sim)
    call progress_report(sim, progress, t_end, .true.)
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
        associate (q => sim%blocks(b)%q, n => sim%blocks(b)%n)
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
    integer :: b, p, off
    rate = 0.0_wp
    all_good = .true.
    do b = 1, size(sim%blocks)
      do p = 1, sim%nphase
        off = (p - 1) * sim%nflow
        call euler_max_rate(sim%blocks(b)%lay, sim%eos(p), sim%shear(p), &
          sim%blocks(b)%q(:, :, :, off + 1:off + sim%nflow), r, good)
        rate = max(rate, r)
        all_good = all_good .and. good
      end do
    end do
    ok = .not. comm_any(.not. all_good)
    rate = comm_max(rate)
    if (.not. rate > 0.0_wp) rate = tiny(1.0_wp)
  end subroutine step_size

  !> One time step of sim%dt by TVD Runge-Kutta of order rk_order.
  subroutine advance(sim)
    type(sim_t), intent(inout) :: sim
    integer :: stage, b, nbad
    integer(i8) :: nfall
    logical :: edge
    real(wp) :: tstage, vwall(2, 3)
    logical :: wall(2, 3)
    real(wp), parameter :: stage_time(3, 3) = reshape([0.0_wp, 0.0_wp, 0.0_wp, &
      0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.5_wp], [3, 3])
    integer :: nf
    logical :: failed
    nf = 0
    failed = .false.
    sim%step_failed = .false.
    if (sim%fix_mass) then
      sim%bflux = 0.0_wp
      sim%lost = 0.0_wp
    end if
    do stage = 1, sim%cfg%rk_order
      tstage = sim%time + stage_time(stage, sim%cfg%rk_order) * sim%dt
      call timer_start(sim%timers, 'halo')
      if (sim%ls%n > 0) then
        ! blocks dormant at the last ghost fill take their level sets only (ghost_fill)
        call halo_exchange(sim%plan, sim%blocks, sim%nvar, skip=sim%dormant, keep=sim%ils + 1)
        call boundary_apply(sim%lay, sim%bc, sim%blocks, sim%nvar, sim%nflow, tstage, &
          sim%nphase, skip=sim%dormant, keep=sim%ils + 1)
      else
        call halo_exchange(sim%plan, sim%blocks, sim%nvar)
        call boundary_apply(sim%lay, sim%bc, sim%blocks, sim%nvar, sim%nflow, tstage, &
          sim%nphase)
      end if
      call timer_stop(sim%timers, 'halo')
      if (sim%ls%n > 0) call ghost_fill(sim, tstage)
      call timer_start(sim%timers, 'fluxes')
      do b = 1, size(sim%blocks)
        call sim_block_work(sim, b)
        associate (blk => sim%blocks(b), n => sim%blocks(b)%n)
          if (sim%ls%n > 0) then
            ! a block of void or rigid interior far from every surface holds a rest state
            ! that nothing changes: no fluxes (DESIGN: void costs nothing)
            if (sim%dormant(b)) then
              if (stage == 1) blk%q0 = blk%q(1:n(1), 1:n(2), 1:n(3), :)
              cycle
            end if
          end if
          call boundary_walls(sim%lay, sim%bc, blk, tstage, wall, vwall)
          ! the stage input, for the cell-local fallback (at stage 1 it is q0, kept anyway)
          if (stage > 1) sim%qsave = blk%q(1:n(1), 1:n(2), 1:n(3), :)
          call block_stage(sim, b, stage, wall, vwall, nf, failed)
          if (failed) exit
          ! the cell-local fallback: cells the update left inadmissible are redone with every
          ! face of theirs at first order (conservative: both neighbours see the same face
          ! flux); a trouble cell on a side the block shares with another block is left to
          ! the step fallback
          call find_trouble(sim, b, nbad, edge)
          if (nbad > 0 .and. .not. edge) then
            if (stage > 1) then
              blk%q(1:n(1), 1:n(2), 1:n(3), :) = sim%qsave
            else
              blk%q(1:n(1), 1:n(2), 1:n(3), :) = blk%q0
            end if
            call block_stage(sim, b, stage, wall, vwall, nf, failed, sim%trouble)
            if (failed) exit
            sim%cells_low = sim%cells_low + nbad
          end if
        end associate
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

  !> One RK stage on block b: right-hand sides of every phase (faces of the trouble cells at
  !> first order when the mask is given), level-set rates, the stage update, radial return,
  !> overlap removal, debris and the rest state outside each phase's region.
  subroutine block_stage(sim, b, stage, wall, vwall, nf, failed, trouble)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b, stage
    logical, intent(in) :: wall(2, 3)
    real(wp), intent(in) :: vwall(2, 3)
    integer, intent(inout) :: nf
    logical, intent(inout) :: failed
    logical, intent(in), optional :: trouble(:, :, :)
    integer :: p, off
    integer :: lo(3), hi(3), n(3)
    logical :: fresh(sim%blocks(b)%n(1), sim%blocks(b)%n(2), sim%blocks(b)%n(3))
    n = sim%blocks(b)%n
    lo = 1 - sim%lay%ng
    hi = n + sim%lay%ng
    associate (blk => sim%blocks(b))
      do p = 1, sim%nphase
        off = (p - 1) * sim%nflow
        if (sim%ls%n > 0 .and. sim%strong(p)) then
          ! the composite level set of the phase at the stage's start: which cells are real
          ! (for the radial return), which faces join two of them (upwind scalar flux) and
          ! which lie on its surface (transported variables at the real cell's value)
          call ls_region(sim%ls, p, lo, hi, blk%q(:, :, :, sim%ils + 1:sim%nvar), &
            sim%gwork%bigphi(:, :, :, p), sim%gwork%owner(:, :, :, p))
          sim%gwork%isreal(:, :, :, p) = sim%gwork%bigphi(:, :, :, p) < 0.0_wp
          call euler_rhs(blk%lay, sim%eos(p), sim%st(p), sim%scheme, sim%flux, &
            sim%scalar_flux, blk%q(:, :, :, off + 1:off + sim%nflow), &
            blk%rhs(:, :, :, off + 1:off + sim%nflow), blk%offset, wall, vwall, sim%work, &
            nf, failed, sim%gwork%bigphi(:, :, :, p), trouble, &
            surface_llf=sim%cfg%surface_flux == 'llf')
          if (sim%fix_mass) sim%bflux(:, p, b, stage) = sim%work%bflux
        else
          call euler_rhs(blk%lay, sim%eos(p), sim%st(p), sim%scheme, sim%flux, &
            sim%scalar_flux, blk%q(:, :, :, off + 1:off + sim%nflow), &
            blk%rhs(:, :, :, off + 1:off + sim%nflow), blk%offset, wall, vwall, sim%work, &
            nf, failed, trouble=trouble)
        end if
      end do
      if (failed) return
      if (sim%ls%n > 0) call levelset_rates(sim, b)
      call rk_stage_update(blk%lay, stage, sim%cfg%rk_order, sim%dt, blk%q, blk%q0, &
        blk%rhs)
      do p = 1, sim%nphase
        off = (p - 1) * sim%nflow
        if (.not. sim%strong(p)) cycle
        if (sim%ls%n > 0) then
          ! the region after the update: its cells that were not real at the start are fresh
          call ls_region(sim%ls, p, lo, hi, blk%q(:, :, :, sim%ils + 1:sim%nvar), &
            sim%gwork%bigphi(:, :, :, p), sim%gwork%owner(:, :, :, p))
          fresh = sim%gwork%bigphi(1:n(1), 1:n(2), 1:n(3), p) < 0.0_wp .and. &
            .not. sim%gwork%isreal(1:n(1), 1:n(2), 1:n(3), p)
          sim%gwork%isreal(:, :, :, p) = sim%gwork%bigphi(:, :, :, p) < 0.0_wp
          call plastic_correction(blk%lay, sim%eos(p), sim%st(p), sim%cfg%thermal, sim%dt, &
            blk%q(:, :, :, off + 1:off + sim%nflow), &
            sim%gwork%isreal(1:n(1), 1:n(2), 1:n(3), p), fresh)
        else
          call plastic_correction(blk%lay, sim%eos(p), sim%st(p), sim%cfg%thermal, sim%dt, &
            blk%q(:, :, :, off + 1:off + sim%nflow))
        end if
      end do
      if (count(sim%ls%kind == ls_material) > 1) call ls_separate(sim%ls, &
        blk%q(1:n(1), 1:n(2), 1:n(3), sim%ils + 1:sim%nvar))
      if (any(sim%ls%kind == ls_material)) call gfm_drop_debris(blk%lay, sim%scn, &
        sim%ls, blk%offset, blk%q, sim%gcount, sim%lost)
      if (sim%ls%n > 0) call gfm_rest(blk%lay, sim%scn, sim%ls, blk%q, sim%gwork)
    end associate
  end subroutine block_stage

  !> The interior cells of block b that hold no admissible state for some phase (rho <= 0,
  !> c^2 <= 0 or not finite) into sim%trouble; edge is true when one lies on a side the block
  !> shares with another block.
  subroutine find_trouble(sim, b, nbad, edge)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b
    integer, intent(out) :: nbad
    logical, intent(out) :: edge
    integer :: j, k, p, off, n, d
    logical :: lo_shared, hi_shared
    real(wp), dimension(sim%blocks(b)%n(1)) :: rho, u, v, w, pr, e, c2
    n = sim%blocks(b)%n(1)
    sim%trouble = .false.
    associate (q => sim%blocks(b)%q)
      do p = 1, sim%nphase
        off = (p - 1) * sim%nflow
        do k = 1, sim%blocks(b)%n(3)
          do j = 1, sim%blocks(b)%n(2)
            rho = q(1:n, j, k, off + i_rho)
            if (all(rho > 0.0_wp .and. abs(q(1:n, j, k, off + i_en)) <= huge(1.0_wp))) then
              call primitive_row(sim%eos(p), n, q(1:n, j, k, off + i_rho), &
                q(1:n, j, k, off + i_mx), q(1:n, j, k, off + i_my), q(1:n, j, k, off + i_mz), &
                q(1:n, j, k, off + i_en), rho, u, v, w, pr, e)
              call eos_sound_speed2(sim%eos(p), n, rho, pr, c2)
              if (all(c2 > 0.0_wp .and. c2 <= huge(1.0_wp))) cycle
              sim%trouble(:, j, k) = sim%trouble(:, j, k) .or. &
                .not. (c2 > 0.0_wp .and. c2 <= huge(1.0_wp))
            else
              sim%trouble(:, j, k) = sim%trouble(:, j, k) .or. .not. (rho > 0.0_wp)
              sim%trouble(:, j, k) = sim%trouble(:, j, k) .or. &
                .not. abs(q(1:n, j, k, off + i_en)) <= huge(1.0_wp)
            end if
          end do
        end do
      end do
    end associate
    nbad = count(sim%trouble)
    edge = .false.
    if (nbad == 0) return
    ! a side shared with another block (not a domain side, unless periodic)
    associate (off3 => sim%blocks(b)%offset, nb => sim%blocks(b)%n, lay => sim%lay)
      do d = 1, lay%ndim
        lo_shared = off3(d) > 0 .or. lay%periodic(d)
        hi_shared = off3(d) + nb(d) < lay%cells(d) .or. lay%periodic(d)
        select case (d)
        case (1)
          edge = edge .or. (lo_shared .and. any(sim%trouble(1, :, :))) .or. &
            (hi_shared .and. any(sim%trouble(nb(1), :, :)))
        case (2)
          edge = edge .or. (lo_shared .and. any(sim%trouble(:, 1, :))) .or. &
            (hi_shared .and. any(sim%trouble(:, nb(2), :)))
        case default
          edge = edge .or. (lo_shared .and. any(sim%trouble(:, :, 1))) .or. &
            (hi_shared .and. any(sim%trouble(:, :, nb(3))))
        end select
      end do
    end associate
  end subroutine find_trouble

  !> The ghost-fluid stage of DESIGN section 5: rigid level sets moved to the stage time,
  !> ghost bands filled on every block (m_gfm), then a second halo exchange of the flow
  !> variables so that each block sees its neighbours' ghosts. A dormant block (every cell,
  !> halo included, beyond every band) is not computed, and its flow halo is not kept: both
  !> exchanges leave it out. Before any fill, a block that was dormant and wakes (its level
  !> sets, always exchanged, now reach into a band) takes the flow halo it missed, from
  !> neighbours not yet filled: the result is that of exchanging every halo every time.
  subroutine ghost_fill(sim, tstage)
    type(sim_t), intent(inout) :: sim
    real(wp), intent(in) :: tstage
    integer :: b, l, i, j, k
    call timer_start(sim%timers, 'gfm')
    do l = 1, sim%ls%n
      if (sim%ls%kind(l) /= ls_rigid .or. .not. any(abs(sim%ls%velocity(:, l)) > 0.0_wp)) cycle
      do b = 1, size(sim%blocks)
        associate (q => sim%blocks(b)%q, body => sim%cfg%bodies(sim%ls%body(l)))
          do k = lbound(q, 3), ubound(q, 3)
            do j = lbound(q, 2), ubound(q, 2)
              do i = lbound(q, 1), ubound(q, 1)
                q(i, j, k, sim%ils + l) = body_distance(body, sim%lay%ndim, &
                  cell_centre(sim%lay, sim%blocks(b)%offset, i, j, k) &
                  - tstage * sim%ls%velocity(:, l))
              end do
            end do
          end do
        end associate
      end do
    end do
    do b = 1, size(sim%blocks)
      if (.not. sim%dormant(b)) cycle
      call sim_block_work(sim, b)
      if (gfm_dormant(sim%blocks(b)%lay, sim%scn, sim%ls, sim%blocks(b)%q, sim%gwork)) cycle
      call halo_refresh(sim%plan, sim%blocks, b, sim%ils, 1)
      call boundary_apply(sim%lay, sim%bc, sim%blocks(b:b), sim%nvar, sim%nflow, tstage, &
        sim%nphase)
    end do
    do b = 1, size(sim%blocks)
      call sim_block_work(sim, b)
      call gfm_fill(sim%blocks(b)%lay, sim%scn, sim%ls, sim%blocks(b)%q, sim%gwork, sim%gcount, &
        sim%dormant(b))
    end do
    call timer_stop(sim%timers, 'gfm')
    call timer_start(sim%timers, 'halo')
    call halo_exchange(sim%plan, sim%blocks, sim%ils, skip=sim%dormant)
    call boundary_apply(sim%lay, sim%bc, sim%blocks, sim%ils, sim%nflow, tstage, sim%nphase, &
      skip=sim%dormant)
    call timer_stop(sim%timers, 'halo')
  end subroutine ghost_fill

  !> Right-hand sides of the level sets of block b: a material body moves with its phase's
  !> velocity (extended into the ghost band by the fill, so it is an extension velocity
  !> there), a void body with the velocity of the phase nearest to each cell, inside the
  !> narrow band |phi| <= band dx; rigid ones are set in ghost_fill and have no rate.
  subroutine levelset_rates(sim, b)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b
    integer :: l, iv, p
    real(wp) :: width
    associate (q => sim%blocks(b)%q, rhs => sim%blocks(b)%rhs, n => sim%blocks(b)%n)
      width = real(sim%cfg%band, wp) * maxval(sim%lay%dx(1:sim%lay%ndim))
      p = -1
      do l = 1, sim%ls%n
        iv = sim%ils + l
        if (sim%ls%kind(l) == ls_rigid) then
          rhs(:, :, :, iv) = 0.0_wp
          cycle
        end if
        if (sim%ls%kind(l) == ls_material) then
          if (sim%ls%phase(l) /= p) call phase_velocity(sim, b, sim%ls%phase(l))
          p = sim%ls%phase(l)
        else
          if (p /= 0) call phase_velocity(sim, b, 0)
          p = 0
        end if
        call levelset_advect_rhs(sim%lay%ndim, n, sim%lay%ng, sim%lay%dx, &
          q(:, :, :, iv), sim%vel, sim%ls_rhs)
        where (abs(q(1:n(1), 1:n(2), 1:n(3), iv)) > width) sim%ls_rhs = 0.0_wp
        rhs(:, :, :, iv) = sim%ls_rhs
      end do
    end associate
  end subroutine levelset_rates

  !> sim%vel on the padded block b: the velocity of phase p, or for p = 0 of the phase whose
  !> composite level set is least at each cell (the phase there, or the nearest one).
  subroutine phase_velocity(sim, b, p)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b, p
    integer :: d, m, off, lo(3), hi(3), i, j, k
    associate (q => sim%blocks(b)%q, w => sim%gwork)
      if (p > 0 .or. sim%nphase == 1) then
        off = (max(p, 1) - 1) * sim%nflow
        do d = 1, 3
          sim%vel(:, :, :, d) = q(:, :, :, off + i_mx + d - 1) / q(:, :, :, off + i_rho)
        end do
        return
      end if
      lo = 1 - sim%lay%ng
      hi = sim%blocks(b)%n + sim%lay%ng
      do m = 1, sim%nphase
        call ls_region(sim%ls, m, lo, hi, q(:, :, :, sim%ils + 1:sim%nvar), &
          w%bigphi(:, :, :, m), w%owner(:, :, :, m))
      end do
      do k = lo(3), hi(3)
        do j = lo(2), hi(2)
          do i = lo(1), hi(1)
            off = (minloc(w%bigphi(i, j, k, :), 1) - 1) * sim%nflow
            sim%vel(i, j, k, :) = q(i, j, k, off + i_mx:off + i_mz) / q(i, j, k, off + i_rho)
          end do
        end do
      end do
    end associate
  end subroutine phase_velocity

  !> Reinitialise the level sets of material and void bodies to signed distances
  !> (m_levelset_reinit): band pseudo-steps of half a cell, so the distance is rebuilt out to
  !> band / 2 cells (3 for the default band of 6, the depth of the ghost band, beyond which
  !> nothing moves the level set), with a halo exchange of the level sets before every RK
  !> stage. The cells next to the surface are frozen: the zero level set stays where the
  !> advection put it.
  subroutine reinitialise(sim)
    type(sim_t), intent(inout) :: sim
    integer :: it, stage, b, l, iv, nls
    type(level_sets_t), allocatable :: phi0(:)
    real(wp), allocatable :: old(:, :, :)
    real(wp) :: dtau
    nls = sim%ls%n
    if (.not. any(sim%ls%kind == ls_material .or. sim%ls%kind == ls_void)) return
    call timer_start(sim%timers, 'reinit')
    call halo_exchange(sim%plan, sim%blocks, sim%nvar, sim%ils + 1)
    call boundary_apply(sim%lay, sim%bc, sim%blocks, sim%nvar, sim%nflow, sim%time, &
      sim%nphase, skip=sim%dormant, keep=sim%ils + 1)
    allocate(phi0(size(sim%blocks)))
    do b = 1, size(sim%blocks)
      phi0(b)%phi = sim%blocks(b)%q(:, :, :, sim%ils + 1:sim%nvar)
    end do
    dtau = 0.5_wp * minval(sim%lay%dx(1:sim%lay%ndim))
    do it = 1, sim%cfg%band
      do stage = 1, 3
        if (it > 1 .or. stage > 1) then
          call halo_exchange(sim%plan, sim%blocks, sim%nvar, sim%ils + 1)
          call boundary_apply(sim%lay, sim%bc, sim%blocks, sim%nvar, sim%nflow, sim%time, &
            sim%nphase, skip=sim%dormant, keep=sim%ils + 1)
        end if
        do b = 1, size(sim%blocks)
          if (allocated(old)) then
            if (any(shape(old) /= sim%blocks(b)%n)) deallocate(old)
          end if
          if (.not. allocated(old)) &
            allocate(old(sim%blocks(b)%n(1), sim%blocks(b)%n(2), sim%blocks(b)%n(3)))
          do l = 1, nls
            if (sim%ls%kind(l) == ls_rigid) cycle
            iv = sim%ils + l
            call save_or_restore(b, l, stage)
            call levelset_reinit_step(sim%lay%ndim, sim%blocks(b)%n, sim%lay%ng, sim%lay%dx, &
              phi0(b)%phi(:, :, :, l), stage, dtau, sim%blocks(b)%q(:, :, :, iv), old, &
              freeze=.true.)
            call keep_rk(b, l)
          end do
        end do
      end do
    end do
    call timer_stop(sim%timers, 'reinit')

  contains

    ! the RK save space of one level set on one block lives in the rhs array (free between
    ! steps)
    subroutine save_or_restore(bb, ll, st)
      integer, intent(in) :: bb, ll, st
      if (st > 1) old = sim%blocks(bb)%rhs(:, :, :, sim%ils + ll)
    end subroutine save_or_restore

    subroutine keep_rk(bb, ll)
      integer, intent(in) :: bb, ll
      sim%blocks(bb)%rhs(:, :, :, sim%ils + ll) = old
    end subroutine keep_rk

  end subroutine reinitialise

  !> The conservation fix of the ghost-fluid method (m_gfm_conserve; manual/interfaces.md
  !> section 2b). Each solid phase's mass and total energy over its real cells are measured
  !> and, when apply is set, compared with their targets: the values at the run's start plus
  !> what came in through the domain's sides (the Runge-Kutta weighted rates of the stages)
  !> less the debris taken out. What lies outside a band around the targets (the measure's own
  !> noise) is returned to the phase's surface cells (within two cells of its surface). The
  !> block sums are added in block order whatever the ranks, so results stay bit-identical on
  !> any number of ranks. sim%fixed keeps what was taken out, for the log and history.csv.
  subroutine conserve_step(sim, apply, changed)
    type(sim_t), intent(inout) :: sim
    logical, intent(in) :: apply
    logical, intent(out), optional :: changed   !< the fix changed the state
    logical :: touched, open_side(sim%nphase)
    integer, parameter :: nq = n_content + 3
    real(wp) :: part(nq, sim%nphase, sim%lay%nblocks), c(nq, sim%nphase), w(3), width, h
    real(wp) :: eps, fm(sim%nphase), a_heat, a_mass, hs, ms, es, e_new(sim%nphase)
    real(wp) :: flat(nq * sim%nphase * sim%lay%nblocks), lost2(2 * sim%nphase)
    real(wp), parameter :: most = 0.1_wp   !< largest share of the surface content per step
    !> the band around the targets inside which nothing is done: above the measure's own
    !> noise (a disc of 8 cells' radius flying obliquely reads +-0.4 % mass, +-0.7 % energy)
    real(wp), parameter :: band_mass = 0.005_wp, band_energy = 0.0075_wp
    integer :: b, p, off, id, s
    h = maxval(sim%lay%dx(1:sim%lay%ndim))
    width = 2.0_wp * h
    w = rk_weights(sim%cfg%rk_order)
    part = 0.0_wp
    do b = 1, size(sim%blocks)
      if (sim%dormant(b)) cycle
      call sim_block_work(sim, b)
      id = sim%blocks(b)%id
      do p = 1, sim%nphase
        if (.not. sim%strong(p)) cycle
        off = (p - 1) * sim%nflow
        call region(b, p)
        call content_block(sim%blocks(b)%lay, sim%blocks(b)%offset, &
          sim%blocks(b)%q(:, :, :, off + 1:off + sim%nflow), sim%gwork%bigphi(:, :, :, p), &
          h, width, part(1:n_content, p, id))
        do s = 1, 3
          part(n_content + 1:n_content + 2, p, id) = part(n_content + 1:n_content + 2, p, id) &
            + w(s) * sim%bflux(:, p, b, s)
        end do
        part(nq, p, id) = open_cells(b, p)
      end do
    end do
    flat = reshape(part, [size(part)])
    call comm_sum_array(flat)
    part = reshape(flat, shape(part))
    c = 0.0_wp
    do id = 1, sim%lay%nblocks
      c = c + part(:, :, id)
    end do
    if (present(changed)) changed = .false.
    if (.not. apply) then
      sim%open_cells = c(nq, :)
      sim%content = c(1:2, :)
      sim%measure = sum(c(1:2, :), dim=2, mask=spread(sim%strong, 1, 2))
      return
    end if
    sim%measure(1) = 0.0_wp
    lost2 = reshape(sim%lost, [size(sim%lost)])
    call comm_sum_array(lost2)
    sim%lost = reshape(lost2, shape(sim%lost))
    ! the targets: the content at the start, moved by what crossed the domain's sides and by
    ! the debris taken out; a phase whose cells on the open (outflow) sides of the domain
    ! have changed in number is left alone as long as it has cells there, its target reset
    ! to its measure (what leaves there cannot be told from what the update loses: the last
    ! half cell of a body leaving goes with its level set); a plate spanning an open side
    ! whose edge stays put keeps its fix
    sim%content = sim%content + sim%dt * c(n_content + 1:n_content + 2, :) - sim%lost
    where (abs(c(nq, :) - sim%open_cells) > 0.0_wp) sim%crossing = 1.0_wp
    where (.not. c(nq, :) > 0.0_wp) sim%crossing = 0.0_wp
    open_side = sim%crossing > 0.0_wp .and. sim%strong
    sim%open_cells = c(nq, :)
    if (any(open_side)) sim%fix_aside = sim%fix_aside + 1
    where (open_side) sim%content(1, :) = c(1, :)
    if (any(open_side)) sim%content(2, :) = c(2, :)
    ! mass, phase by phase: a factor on the surface cells
    fm = 1.0_wp
    do p = 1, sim%nphase
      if (.not. sim%strong(p)) cycle
      eps = 0.0_wp
      if (c(3, p) > 0.0_wp .and. .not. open_side(p)) then
        eps = outside(c(1, p), sim%content(1, p), band_mass)
        if (abs(eps) > most * c(3, p)) sim%fix_clamped = sim%fix_clamped + 1
        eps = max(-most * c(3, p), min(most * c(3, p), eps))
        fm(p) = 1.0_wp - eps / c(3, p)
      end if
      sim%fixed(1, p) = sim%fixed(1, p) + eps
      sim%measure(1) = sim%measure(1) + c(1, p) - eps
    end do
    ! energy, all solid phases together: an excess out of the internal energy, a deficit
    ! into it in proportion to mass
    e_new = c(2, :) + (fm - 1.0_wp) * c(4, :)
    a_heat = 0.0_wp
    a_mass = 0.0_wp
    if (sim%fix_energy .and. .not. any(open_side)) then
      eps = outside(sum(e_new, mask=sim%strong), sum(sim%content(2, :), mask=sim%strong), &
        band_energy)
      hs = sum(fm * c(5, :), mask=sim%strong)
      ms = sum(fm * c(3, :), mask=sim%strong)
      es = sum(fm * abs(c(4, :)), mask=sim%strong)
      if (eps > 0.0_wp .and. hs > 0.0_wp) then
        ! out of the heat where there is some, the rest (cold material) in proportion to mass
        a_heat = -min(eps, most * hs) / hs
        eps = eps + a_heat * hs
      end if
      if (abs(eps) > most * es) sim%fix_clamped = sim%fix_clamped + 1
      eps = max(-most * es, min(most * es, eps))
      if (ms > 0.0_wp) a_mass = -eps / ms
      do p = 1, sim%nphase
        if (.not. sim%strong(p)) cycle
        sim%fixed(2, p) = sim%fixed(2, p) - a_heat * fm(p) * c(5, p) - a_mass * fm(p) * c(3, p)
        e_new(p) = e_new(p) + a_heat * fm(p) * c(5, p) + a_mass * fm(p) * c(3, p)
      end do
    end if
    sim%measure(2) = sum(e_new, mask=sim%strong)
    touched = any(abs(fm - 1.0_wp) > 0.0_wp) .or. abs(a_heat) + abs(a_mass) > 0.0_wp
    if (present(changed)) changed = touched
    if (.not. touched) return
    do b = 1, size(sim%blocks)
      if (sim%dormant(b)) cycle
      call sim_block_work(sim, b)
      do p = 1, sim%nphase
        ! a block with no surface cell of the phase has nothing to fix
        if (.not. (sim%strong(p) .and. part(3, p, sim%blocks(b)%id) > 0.0_wp)) cycle
        off = (p - 1) * sim%nflow
        call region(b, p)
        call fix_block(sim%blocks(b)%lay, sim%blocks(b)%q(:, :, :, off + 1:off + sim%nflow), &
          sim%gwork%bigphi(:, :, :, p), width, fm(p), a_heat, a_mass)
      end do
    end do

  contains

    !> the real cells of phase pp in block bb on the outflow sides of the domain
    real(wp) function open_cells(bb, pp) result(cnt)
      integer, intent(in) :: bb, pp
      integer :: d, n(3), off3(3)
      cnt = 0.0_wp
      n = sim%blocks(bb)%n
      off3 = sim%blocks(bb)%offset
      do d = 1, sim%lay%ndim
        if (sim%bc%lo(d) == bc_outflow .and. off3(d) == 0) cnt = cnt + layer(bb, d, 1, pp)
        if (sim%bc%hi(d) == bc_outflow .and. off3(d) + n(d) == sim%lay%cells(d)) &
          cnt = cnt + layer(bb, d, n(d), pp)
      end do
    end function open_cells

    !> the real cells of phase pp in layer m of direction d of block bb (region() was given it)
    real(wp) function layer(bb, d, m, pp) result(cnt)
      integer, intent(in) :: bb, d, m, pp
      integer :: lo3(3), hi3(3)
      lo3 = 1
      hi3 = sim%blocks(bb)%n
      lo3(d) = m
      hi3(d) = m
      cnt = real(count(sim%gwork%bigphi(lo3(1):hi3(1), lo3(2):hi3(2), lo3(3):hi3(3), pp) &
        < 0.0_wp), wp)
    end function layer

    !> how far x lies outside target t (1 -+ band)
    pure real(wp) function outside(x, t, band) result(d)
      real(wp), intent(in) :: x, t, band
      d = x - max(t - band * abs(t), min(t + band * abs(t), x))
    end function outside

    subroutine region(bb, pp)
      integer, intent(in) :: bb, pp
      call ls_region(sim%ls, pp, 1 - sim%lay%ng, sim%blocks(bb)%n + sim%lay%ng, &
        sim%blocks(bb)%q(:, :, :, sim%ils + 1:sim%nvar), sim%gwork%bigphi(:, :, :, pp), &
        sim%gwork%owner(:, :, :, pp))
    end subroutine region

  end subroutine conserve_step

end module m_timeloop
