!> Advection of a level set on one block (manual/theory.md section 6):
!> phi_t + u . grad phi = 0, so rhs = -sum_d u_d phi_d with phi_d the upwind one-sided
!> HJ-WENO5 (default) or HJ-ENO3 derivative of m_levelset_derivatives: phi_d^- where u_d > 0,
!> phi_d^+ where u_d < 0. Time stepping is the TVD RK3 of Shu and Osher in the convex form of
!> m_euler's rk_stage_update. The velocity is cell-centred on the same padded shape as phi
!> (only its interior is read); g >= 4 halo cells in every active direction, g = 0 in the
!> others. The kernels neither fill nor exchange the halo (the caller does, before every
!> stage), build no extension velocities and know nothing of a narrow band: they work on the
!> whole block.
module m_levelset_advect
  use m_kinds, only: wp
  use m_reconstruct, only: scheme_weno5
  use m_levelset_derivatives, only: levelset_one_sided
  implicit none
  private
  public :: levelset_advect_rhs, levelset_rk_stage

contains

  !> rhs(n1, n2, n3) = -u . grad phi at the interior cells; scheme is scheme_weno5 (default)
  !> or scheme_eno3 of m_reconstruct.
  subroutine levelset_advect_rhs(ndim, n, g, dx, phi, vel, rhs, scheme)
    integer, intent(in) :: ndim, n(3), g(3)
    real(wp), intent(in) :: dx(3)
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(in) :: vel(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3), 3)
    real(wp), intent(out) :: rhs(n(1), n(2), n(3))
    integer, intent(in), optional :: scheme
    real(wp), allocatable :: dm(:, :, :), dp(:, :, :)
    real(wp) :: u
    integer :: d, i, j, k, sch
    sch = scheme_weno5
    if (present(scheme)) sch = scheme
    allocate(dm(n(1), n(2), n(3)), dp(n(1), n(2), n(3)))
    rhs = 0.0_wp
    do d = 1, ndim
      call levelset_one_sided(sch, d, n, g, dx, phi, dm, dp)
      do k = 1, n(3)
        do j = 1, n(2)
          do i = 1, n(1)
            u = vel(i, j, k, d)
            rhs(i, j, k) = rhs(i, j, k) - (max(u, 0.0_wp) * dm(i, j, k) &
              + min(u, 0.0_wp) * dp(i, j, k))
          end do
        end do
      end do
    end do
  end subroutine levelset_advect_rhs

  !> One stage (1, 2, 3) of TVD RK3 on the interior of phi: stage 1 saves phi in phi_old and
  !> takes an Euler step; stages 2 and 3 take the convex combinations 3/4, 1/4 and 1/3, 2/3.
  !> live (optional): only these cells are updated (and saved); the others keep their values
  !> bit for bit (m_levelset_reinit's narrow band).
  subroutine levelset_rk_stage(n, g, stage, dt, phi, phi_old, rhs, live)
    integer, intent(in) :: n(3), g(3), stage
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(inout) :: phi_old(n(1), n(2), n(3))
    real(wp), intent(in) :: rhs(n(1), n(2), n(3))
    logical, intent(in), optional :: live(n(1), n(2), n(3))
    real(wp) :: a
    if (stage == 1) then
      if (present(live)) then
        where (live) phi_old = phi(1:n(1), 1:n(2), 1:n(3))
        where (live) phi(1:n(1), 1:n(2), 1:n(3)) = phi_old + dt * rhs
        return
      end if
      phi_old = phi(1:n(1), 1:n(2), 1:n(3))
      phi(1:n(1), 1:n(2), 1:n(3)) = phi_old + dt * rhs
      return
    end if
    if (stage == 2) then
      a = 0.75_wp
    else
      a = 1.0_wp / 3.0_wp
    end if
    if (present(live)) then
      where (live) phi(1:n(1), 1:n(2), 1:n(3)) = a * phi_old &
        + (1.0_wp - a) * (phi(1:n(1), 1:n(2), 1:n(3)) + dt * rhs)
      return
    end if
    phi(1:n(1), 1:n(2), 1:n(3)) = a * phi_old &
      + (1.0_wp - a) * (phi(1:n(1), 1:n(2), 1:n(3)) + dt * rhs)
  end subroutine levelset_rk_stage

end module m_levelset_advect
