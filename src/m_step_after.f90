!> What the time loop (m_timeloop) does to a step after m_step has taken it, before output:
!> - the step fallback (m_fallback) when the step left a cell inadmissible: the state back to
!>   the step's start and the step again at first order in space (redo_first_order);
!> - the corrections: the level sets' reinitialisation every reinit_every steps (those of
!>   material and void bodies, m_levelset_reinit) and the conservation fix (m_gfm_conserve),
!>   with the next step's signal rate from the corrected state.
!> The corrections do nothing on a deck without what they correct. The numerics live in the
!> modules named; this calls them on the run's state.
module m_step_after
  use m_kinds, only: wp
  use m_simulation, only: sim_t, sim_rate
  use m_step, only: advance
  use m_euler, only: numerics_t
  use m_fallback, only: fallback_step, fallback_numerics
  use m_levelset_bodies, only: ls_material, ls_void
  use m_levelset_reinit, only: levelset_reinitialise
  use m_gfm_conserve, only: conserve_fix
  use m_timers, only: timer_start, timer_stop
  implicit none
  private
  public :: step_fallback, step_corrections, conserve_start

contains

  !> The step fallback for the step just taken: ok on return when the redo left every cell
  !> admissible, and then rate is the next step's signal rate.
  subroutine step_fallback(sim, rate, ok)
    type(sim_t), intent(inout) :: sim
    real(wp), intent(inout) :: rate
    logical, intent(out) :: ok
    call fallback_step(sim, sim%clk%step + 1, sim%clk%dt, sim%diag%first_order_steps + 1, &
      redo_first_order, ok)
    sim%diag%first_order_steps = sim%diag%first_order_steps + 1
    if (ok) call sim_rate(sim, rate, ok)
  end subroutine step_fallback

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
      ! (the step's start: no block's rest states are known to be in place, m_gfm's gf_t)
      if (allocated(sim%gf%rested)) sim%gf%rested = .false.
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

  !> The corrections after the step (which has not yet advanced sim%clk): the reinitialisation
  !> when due, and, when ok (the state admissible), the conservation fix; ok false on return
  !> when the fixed state has no signal rate.
  subroutine step_corrections(sim, rate, ok)
    type(sim_t), intent(inout) :: sim
    real(wp), intent(inout) :: rate
    logical, intent(inout) :: ok
    logical :: changed, moves(sim%ls%n)
    integer :: k
    ! the level sets that reinitialisation rebuilds: those of material and void bodies
    moves = sim%ls%kind == ls_material .or. sim%ls%kind == ls_void
    if (mod(sim%clk%step + 1, sim%cfg%reinit_every) == 0 .and. any(moves)) then
      call timer_start(sim%timers, 'reinit')
      call levelset_reinitialise(sim%plan, sim%lay, sim%bc, sim%ph, sim%blocks, moves, &
        sim%cfg%band, sim%clk%time, sim%gf%dormant)
      ! (the cut-cell geometry of the level sets before it no longer holds)
      do k = 1, size(sim%cut)
        if (allocated(sim%cut(k)%kept)) sim%cut(k)%kept = .false.
      end do
      call timer_stop(sim%timers, 'reinit')
    end if
    if (sim%fix%on .and. ok) then
      call timer_start(sim%timers, 'gfm')
      call conserve_fix(sim%fix, sim%lay, sim%bc, sim%ls, sim%ph, sim%gf, sim%blocks, &
        sim%cfg%rk_order, sim%clk%dt, .true., changed)
      call timer_stop(sim%timers, 'gfm')
      ! the next step's size from the fixed state (as a restart from here would have it)
      if (changed) call sim_rate(sim, rate, ok)
    end if
  end subroutine step_corrections

  !> The conservation fix's targets at a fresh run's start: the content of each phase then
  !> (nothing without the fix; a restart reads them from its checkpoint).
  subroutine conserve_start(sim)
    type(sim_t), intent(inout) :: sim
    if (.not. sim%fix%on) return
    call conserve_fix(sim%fix, sim%lay, sim%bc, sim%ls, sim%ph, sim%gf, sim%blocks, &
      sim%cfg%rk_order, sim%clk%dt, .false.)
    sim%fix%content0 = sum(sim%fix%content, dim=2)
  end subroutine conserve_start

end module m_step_after
