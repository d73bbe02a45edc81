!> One time step of sim%clk%dt (DESIGN section 5), as a recipe: the TVD Runge-Kutta stages,
!> each of them
!>   fill ghosts (halo exchange + side conditions)     m_boundary
!>   ghost-fluid stage and the flow ghosts again        m_gfm_stage, m_boundary
!>   on every block: the phases' right-hand sides, the level sets' rates, the stage update,
!>   the phases' corrections, and the cell-local fallback   m_gfm_stage, m_levelset_motion,
!>                                                          m_euler, m_fallback
!> With &run overlap on a deck without level sets, where the flow ghosts are the only ghost
!> step, the fill is split in two (fill_ghosts' part) and the blocks that take
!> nothing from other ranks are computed while the halo messages travel, the others after
!> them: a block's stage reads its own cells and halo alone, so the order of the blocks
!> changes no result (DESIGN section 5).
!> The numerics live in the modules named; this strings them together.
module m_step
  use m_kinds, only: wp, i8
  use m_simulation, only: sim_t, sim_block_work
  use m_boundary, only: fill_ghosts, ghosts_all, ghosts_flow, boundary_walls, ghosts_start, &
    ghosts_finish
  use m_runge_kutta, only: rk_stage_update
  use m_fallback, only: find_trouble
  use m_levelset_motion, only: levelset_rates
  use m_gfm_stage, only: ghost_fluid_fill, phase_rhs, phase_corrections, phase_states, states_end
  use m_comm, only: comm_any, comm_sum
  use m_balance, only: balance_now, balance_add
  use m_timers, only: timer_start, timer_stop
  use m_phase_heat, only: phase_heat
  use m_gfm_conserve, only: fix_step_start
  implicit none
  private
  public :: advance

  !> the time of each stage within the step, in units of dt, for RK orders 1, 2 and 3
  real(wp), parameter :: stage_time(3, 3) = reshape([0.0_wp, 0.0_wp, 0.0_wp, &
    0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.5_wp], [3, 3])

contains

  !> One step by TVD Runge-Kutta of order rk_order. A stage whose state has no admissible
  !> cell values somewhere ends the step on every rank (sim%diag%step_failed): the caller
  !> recomputes it at first order (m_fallback).
  subroutine advance(sim)
    type(sim_t), intent(inout) :: sim
    integer :: stage, b, nf
    logical :: failed
    real(wp) :: t
    nf = 0
    failed = .false.
    sim%diag%step_failed = .false.
    call fix_step_start(sim%fix)
    do stage = 1, sim%cfg%rk_order
      t = sim%clk%time + stage_time(stage, sim%cfg%rk_order) * sim%clk%dt
      if (sim%overlap) then
        call timer_start(sim%timers, 'halo')
        call fill_ghosts(sim%plan, sim%lay, sim%bc, sim%blocks, sim%ph, ghosts_all, t, &
          sim%gf%dormant, part=ghosts_start)
        call timer_stop(sim%timers, 'halo')
        call stage_blocks(sim, stage, t, .not. sim%plan%remote, nf, failed)
        call timer_start(sim%timers, 'halo')
        call fill_ghosts(sim%plan, sim%lay, sim%bc, sim%blocks, sim%ph, ghosts_all, t, &
          sim%gf%dormant, part=ghosts_finish)
        call timer_stop(sim%timers, 'halo')
        if (.not. failed) call stage_blocks(sim, stage, t, sim%plan%remote, nf, failed)
      else
        call timer_start(sim%timers, 'halo')
        call fill_ghosts(sim%plan, sim%lay, sim%bc, sim%blocks, sim%ph, ghosts_all, t, &
          sim%gf%dormant)
        call timer_stop(sim%timers, 'halo')
        if (sim%ls%n > 0) then
          call timer_start(sim%timers, 'gfm')
          call ghost_fluid_fill(sim%gf, sim%cut, sim%ls, sim%ph, sim%plan, sim%lay, sim%bc, &
            sim%cfg%bodies, sim%made, sim%blocks, t, stage, sim%clk%dt, sim%cfg%thermal, failed)
          call timer_stop(sim%timers, 'gfm')
          ! (only the fluxes' pencils read this halo: the faces, when the scene allows it)
          call timer_start(sim%timers, 'halo')
          if (sim%flow_faces) then
            call fill_ghosts(sim%plan_flow, sim%lay, sim%bc, sim%blocks, sim%ph, ghosts_flow, &
              t, sim%gf%dormant)
          else
            call fill_ghosts(sim%plan, sim%lay, sim%bc, sim%blocks, sim%ph, ghosts_flow, t, &
              sim%gf%dormant)
          end if
          call timer_stop(sim%timers, 'halo')
        end if
        call stage_blocks(sim, stage, t, [(.true., b = 1, size(sim%blocks))], nf, failed)
      end if
      sim%diag%step_failed = comm_any(failed)
      if (sim%diag%step_failed) exit
    end do
    ! a cut-cell phase's content into states (m_gfm_cut; nothing to do without one), timed
    ! with the ghost fill, which holds the cut path's other passes
    if (.not. sim%diag%step_failed) then
      call timer_start(sim%timers, 'gfm')
      call phase_states(sim%gf, sim%cut, sim%ls, sim%ph, sim%plan, sim%lay, sim%bc, &
        sim%blocks, sim%clk%time + sim%clk%dt, sim%clk%dt, sim%cfg%rk_order, &
        sim%cfg%thermal, states_end, sim%diag%step_failed)
      call timer_stop(sim%timers, 'gfm')
    end if
    ! heat conduction and reaction, once per step (m_phase_heat; only when the deck has them)
    if ((sim%ph%has_conduction .or. sim%ph%has_reaction) .and. .not. sim%diag%step_failed) then
      call timer_start(sim%timers, 'heat')
      call phase_heat(sim%gf, sim%ls, sim%ph, sim%fix, sim%plan, sim%lay, sim%bc, sim%blocks, &
        sim%clk%time + sim%clk%dt, sim%clk%dt)
      call timer_stop(sim%timers, 'heat')
    end if
    sim%diag%fallback_faces = sim%diag%fallback_faces + int(nf, i8)
    sim%diag%fallback_step = comm_sum(int(nf, i8))
  end subroutine advance

  !> One RK stage on the blocks b with which(b) set, in order, their ghosts filled: each
  !> its stage and its cell-local fallback. failed: a stage left a cell with no admissible
  !> state (the blocks after it are left undone: the step is redone).
  subroutine stage_blocks(sim, stage, t, which, nf, failed)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: stage
    real(wp), intent(in) :: t
    logical, intent(in) :: which(:)
    integer, intent(inout) :: nf
    logical, intent(inout) :: failed
    integer :: b, nbad
    logical :: edge, wall(2, 3)
    real(wp) :: vwall(2, 3), t_block(2)
    integer :: content(size(sim%cut))   !< the cut phases (0: none)
    content = sim%cut%p
    call timer_start(sim%timers, 'fluxes')
    do b = 1, size(sim%blocks)
      if (.not. which(b)) cycle
      call sim_block_work(sim, b)
      associate (blk => sim%blocks(b), n => sim%blocks(b)%n)
        ! a block of void or rigid interior far from every surface holds a rest state
        ! that nothing changes: no fluxes (DESIGN: void costs nothing)
        if (sim%gf%dormant(b)) then
          if (stage == 1) blk%q0 = blk%q(1:n(1), 1:n(2), 1:n(3), :)
          cycle
        end if
        t_block = balance_now()
        call boundary_walls(sim%lay, sim%bc, blk, t, wall, vwall)
        call block_stage(sim, b, stage, wall, vwall, nf, failed)
        if (failed) exit
        ! the cell-local fallback: the stage again with every face of the cells it left
        ! inadmissible at first order (one on a side shared with another block is left
        ! to the step fallback)
        call find_trouble(sim%lay, sim%ph, blk, sim%wk%trouble, nbad, edge, content)
        if (nbad > 0 .and. .not. edge) then
          if (stage > 1) then
            blk%q(1:n(1), 1:n(2), 1:n(3), :) = sim%wk%qsave
          else
            blk%q(1:n(1), 1:n(2), 1:n(3), :) = blk%q0
          end if
          call block_stage(sim, b, stage, wall, vwall, nf, failed, sim%wk%trouble)
          if (failed) exit
          sim%diag%cells_low = sim%diag%cells_low + nbad
        end if
        ! the block's work, for the load balance (m_balance)
        call balance_add(sim%bal, b, t_block)
      end associate
    end do
    call timer_stop(sim%timers, 'fluxes')
  end subroutine stage_blocks

  !> One RK stage on block b: the right-hand sides of every phase (the faces of the trouble
  !> cells at first order when the mask is given) and of the level sets, the stage update,
  !> the phases' corrections.
  subroutine block_stage(sim, b, stage, wall, vwall, nf, failed, trouble)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b, stage
    logical, intent(in) :: wall(2, 3)
    real(wp), intent(in) :: vwall(2, 3)
    integer, intent(inout) :: nf
    logical, intent(inout) :: failed
    logical, intent(in), optional :: trouble(:, :, :)
    integer :: p, kept(2)
    logical :: idle(sim%ph%nvar)   !< the variables of the phases absent from the block
    if (.not. allocated(sim%gf%absent)) allocate(sim%gf%absent(sim%ph%nphase))
    sim%gf%absent = .false.
    do p = 1, sim%ph%nphase
      call phase_rhs(sim%gf, sim%cut, sim%ls, sim%ph, sim%num, sim%fix, sim%blocks(b), b, p, &
        stage, wall, vwall, sim%wk%euler, nf, failed, trouble)
    end do
    if (failed) return
    if (sim%ls%n > 0) call levelset_rates(sim%lay, sim%ls, sim%ph, sim%cfg%band, &
      sim%blocks(b), sim%gf%vel, sim%gf%ls_rhs, sim%gf%work%bigphi, sim%gf%work%owner)
    ! (a cut-cell phase's variables are only kept: its own update makes its stage content)
    kept = [1, 0]
    if (sim%cut(1)%on) kept = [sim%ph%lo(minval(sim%cut%p)), sim%ph%hi(maxval(sim%cut%p))]
    ! (a phase absent from the block is not updated: every cell of it takes the rest state
    ! after the update, phase_corrections)
    idle = .false.
    do p = 1, sim%ph%nphase
      if (sim%gf%absent(p)) idle(sim%ph%lo(p):sim%ph%hi(p)) = .true.
    end do
    associate (blk => sim%blocks(b))
      ! the stage input is kept for the cell-local fallback (at stage 1 it is q0 anyway)
      if (stage > 1) then
        call rk_stage_update(blk%lay, stage, sim%cfg%rk_order, sim%clk%dt, blk%q, blk%q0, &
          blk%rhs, sim%wk%qsave, kept=kept, idle=idle)
      else
        call rk_stage_update(blk%lay, stage, sim%cfg%rk_order, sim%clk%dt, blk%q, blk%q0, &
          blk%rhs, kept=kept, idle=idle)
      end if
    end associate
    call phase_corrections(sim%gf, sim%cut, sim%ls, sim%ph, sim%fix, sim%blocks(b), b, stage, &
      sim%cfg%rk_order, sim%clk%dt, sim%cfg%thermal)
  end subroutine block_stage

end module m_step
