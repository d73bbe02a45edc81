!> The TVD Runge-Kutta steps of Shu and Osher (1988) that every update shares: the stage
!> update of the interior (rk_stage_update), the weight of the step's start in a stage
!> (rk_blend), and the weight of each stage's right-hand side in the whole step (rk_weights,
!> what crossed a face in a step, for the budgets); and the largest signal rate of a block,
!> which sets the step (euler_max_rate).
module m_runge_kutta
  use m_kinds, only: wp
  use m_layout, only: layout_t
  use m_eos, only: eos_t, eos_sound_speed2
  use m_elastoplastic, only: primitive_row
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en
  implicit none
  private
  public :: rk_stage_update, rk_weights, rk_blend, euler_max_rate

contains

  !> TVD Runge-Kutta stage (Shu and Osher 1988): q = a q0 + b (q + dt rhs) on the interior.
  !> Variables kept(1)..kept(2), when given, are only kept (into q0 at stage 1, into save),
  !> not updated: a cut-cell phase, whose stage content its own update makes (m_gfm_cut's
  !> cut_update, which overwrites them). Variables with idle(m), when given, are neither
  !> updated nor their rates read: a phase absent from the block (m_gfm_stage's phase_rhs),
  !> whose cells all take the rest state after the stage.
  subroutine rk_stage_update(lay, stage, order, dt, q, q0, rhs, save, kept, idle)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: stage, order
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(inout) :: q0(:, :, :, :)
    real(wp), intent(in) :: rhs(:, :, :, :)
    !> at a stage > 1, the stage's input (the interior of q) kept here on the way, for the
    !> cell-local fallback (m_step); at stage 1 it is q0
    real(wp), intent(out), optional :: save(:, :, :, :)
    integer, intent(in), optional :: kept(2)
    !> variables not updated either (kept as they are, their rates not read)
    logical, intent(in), optional :: idle(:)
    real(wp) :: a, b
    integer :: n1, n2, n3, i, j, k, m
    logical :: upd(size(q, 4))
    n1 = lay%bsize(1)
    n2 = lay%bsize(2)
    n3 = lay%bsize(3)
    upd = .true.
    if (present(kept)) upd(kept(1):kept(2)) = .false.
    if (present(idle)) upd = upd .and. .not. idle
    if (stage == 1) then
      q0 = q(1:n1, 1:n2, 1:n3, :)
      if (all(upd)) then
        q(1:n1, 1:n2, 1:n3, :) = q0 + dt * rhs
        return
      end if
      do m = 1, size(q, 4)
        if (upd(m)) q(1:n1, 1:n2, 1:n3, m) = q0(:, :, :, m) + dt * rhs(:, :, :, m)
      end do
      return
    end if
    a = rk_blend(stage, order)
    b = 1.0_wp - a
    if (.not. present(save)) then
      if (all(upd)) then
        q(1:n1, 1:n2, 1:n3, :) = a * q0 + b * (q(1:n1, 1:n2, 1:n3, :) + dt * rhs)
        return
      end if
      do m = 1, size(q, 4)
        if (upd(m)) q(1:n1, 1:n2, 1:n3, m) = a * q0(:, :, :, m) &
          + b * (q(1:n1, 1:n2, 1:n3, m) + dt * rhs(:, :, :, m))
      end do
      return
    end if
    ! (one pass over q for both: the copy was a pass of its own)
    do m = 1, size(q, 4)
      if (.not. upd(m)) then
        save(:, :, :, m) = q(1:n1, 1:n2, 1:n3, m)
        cycle
      end if
      do k = 1, n3
        do j = 1, n2
          do i = 1, n1
            save(i, j, k, m) = q(i, j, k, m)
            q(i, j, k, m) = a * q0(i, j, k, m) + b * (q(i, j, k, m) + dt * rhs(i, j, k, m))
          end do
        end do
      end do
    end do
  end subroutine rk_stage_update

  !> The weight a of the step's start in stage `stage` (> 1) of the TVD Runge-Kutta step:
  !> q = a q0 + (1 - a) (q + dt rhs).
  pure real(wp) function rk_blend(stage, order) result(a)
    integer, intent(in) :: stage, order
    if (order == 2) then
      a = 0.5_wp
    else if (stage == 2) then
      a = 0.75_wp
    else
      a = 1.0_wp / 3.0_wp
    end if
  end function rk_blend

  !> The weight of each stage's right-hand side in the step that rk_stage_update makes: the
  !> step adds dt times the sum of weight(s) L(q_s) (what crossed a face in a step).
  pure function rk_weights(order) result(w)
    integer, intent(in) :: order
    real(wp) :: w(3)
    select case (order)
    case (1)
      w = [1.0_wp, 0.0_wp, 0.0_wp]
    case (2)
      w = [0.5_wp, 0.5_wp, 0.0_wp]
    case default
      w = [1.0_wp, 1.0_wp, 4.0_wp] / 6.0_wp
    end select
  end function rk_weights


  !> Largest sum over directions of (|u_d| + c) / dx_d over the interior: dt = cfl / rate.
  !> Also reports whether every interior cell is admissible (rho > 0, c^2 > 0, finite).
  subroutine euler_max_rate(lay, eos, shear, q, rate, admissible)
    type(layout_t), intent(in) :: lay
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: shear
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(out) :: rate
    logical, intent(out) :: admissible
    integer :: j, k, i, n
    real(wp) :: r, c2(lay%bsize(1)), rdx(3)
    real(wp) :: rho(lay%bsize(1)), u(lay%bsize(1)), v(lay%bsize(1)), w(lay%bsize(1))
    real(wp) :: p(lay%bsize(1)), e(lay%bsize(1))
    n = lay%bsize(1)
    rdx = 0.0_wp
    rdx(1:lay%ndim) = 1.0_wp / lay%dx(1:lay%ndim)
    rate = 0.0_wp
    admissible = .true.
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        if (any(.not. (q(1:n, j, k, i_rho) > 0.0_wp))) then
          admissible = .false.
          cycle
        end if
        call primitive_row(eos, n, q(1:n, j, k, i_rho), q(1:n, j, k, i_mx), &
          q(1:n, j, k, i_my), q(1:n, j, k, i_mz), q(1:n, j, k, i_en), rho, u, v, w, p, e)
        call eos_sound_speed2(eos, n, rho, p, c2)
        c2 = c2 + (4.0_wp / 3.0_wp) * shear / rho
        do i = 1, n
          if (.not. (c2(i) > 0.0_wp .and. c2(i) < huge(1.0_wp))) then
            admissible = .false.
            cycle
          end if
          r = sqrt(c2(i)) * sum(rdx) + abs(u(i)) * rdx(1) + abs(v(i)) * rdx(2) &
            + abs(w(i)) * rdx(3)
          rate = max(rate, r)
        end do
      end do
    end do
  end subroutine euler_max_rate

end module m_runge_kutta
