!> Heat conduction within one phase (Fourier's law, constant conductivity; manual/reaction.md
!> section 2, theory.md eq. 8.5): d(rho E)/dt = div(k grad T), explicit, on one block with
!> its halo. The face flux k (T_R - T_L) / dx is taken only between two real cells of the
!> phase (the mask), so no heat goes into the void, a ghost band or another phase, and the
!> domain's sides conduct what their side conditions put in the halo (outflow: none). In
!> axisymmetric geometry the radial fluxes are r-weighted as the Euler fluxes are (eq. 1.1),
!> so the heat is conserved in the volume 2 pi r dr dz. Also the stable step's rate:
!> forward Euler is stable for dt <= 1 / (2 alpha sum_d 1/dx_d^2), alpha = k / (rho cv).
!> Kernels only: bounds and arrays in, arrays out; no MPI, no I/O, no allocation.
module m_conduction
  use m_kinds, only: wp
  use m_layout, only: layout_t
  implicit none
  private
  public :: conduct_block, conduction_rate

contains

  !> en (rho E of the interior) += dt div(k grad T), with T and the mask on the padded block.
  subroutine conduct_block(lay, offset, kcond, dt, temp, isreal, en)
    type(layout_t), intent(in) :: lay           !< the block's view of the layout
    integer, intent(in) :: offset(3)
    real(wp), intent(in) :: kcond, dt
    real(wp), intent(in) :: temp(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    logical, intent(in) :: isreal(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp), intent(inout) :: en(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp) :: flux(0:lay%bsize(1)), wlo, whi, rf, rc, c(3)
    integer :: i, j, k, d, n(3), e(3)
    n = lay%bsize
    c = 0.0_wp
    c(1:lay%ndim) = kcond * dt / lay%dx(1:lay%ndim)**2
    ! x: a row of face fluxes at a time (r-weighted in axisymmetry)
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 0, n(1)
          flux(i) = merge(temp(i + 1, j, k) - temp(i, j, k), 0.0_wp, &
            isreal(i, j, k) .and. isreal(i + 1, j, k))
        end do
        do i = 1, n(1)
          if (.not. isreal(i, j, k)) cycle
          wlo = 1.0_wp
          whi = 1.0_wp
          if (lay%axisymmetric) then
            rf = lay%lo(1) + real(offset(1) + i - 1, wp) * lay%dx(1)
            rc = rf + 0.5_wp * lay%dx(1)
            wlo = rf / rc
            whi = (rf + lay%dx(1)) / rc
          end if
          en(i, j, k) = en(i, j, k) + c(1) * (whi * flux(i) - wlo * flux(i - 1))
        end do
      end do
    end do
    ! y and z: the difference of the two faces of each cell
    do d = 2, lay%ndim
      e = 0
      e(d) = 1
      do k = 1, n(3)
        do j = 1, n(2)
          do i = 1, n(1)
            if (.not. isreal(i, j, k)) cycle
            en(i, j, k) = en(i, j, k) + c(d) * ( &
              merge(temp(i + e(1), j + e(2), k + e(3)) - temp(i, j, k), 0.0_wp, &
                isreal(i + e(1), j + e(2), k + e(3))) &
              - merge(temp(i, j, k) - temp(i - e(1), j - e(2), k - e(3)), 0.0_wp, &
                isreal(i - e(1), j - e(2), k - e(3))))
          end do
        end do
      end do
    end do
  end subroutine conduct_block

  !> The rate 2 alpha_max sum_d 1/dx_d^2 over the interior's real cells (dt <= 1 / rate is
  !> stable), alpha = k / (rho cv).
  pure real(wp) function conduction_rate(lay, kcond, cv, rho) result(rate)
    type(layout_t), intent(in) :: lay
    real(wp), intent(in) :: kcond, cv
    real(wp), intent(in) :: rho(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp) :: rho_min
    rho_min = minval(rho(1:lay%bsize(1), 1:lay%bsize(2), 1:lay%bsize(3)))
    rate = 0.0_wp
    if (rho_min > 0.0_wp) rate = 2.0_wp * kcond / (rho_min * cv) &
      * sum(1.0_wp / lay%dx(1:lay%ndim)**2)
  end function conduction_rate

end module m_conduction
