!> Geometry of a level set on one block (manual/theory.md section 6; phi < 0 inside a body):
!> unit normals n = grad phi / |grad phi| by central differences (second order, or fourth
!> order on request: the 4-deep halo allows it), zero where |grad phi| vanishes; the
!> curvature kappa = div n = (sum_d phi_dd |grad phi|^2 - sum_de phi_d phi_e phi_de) /
!> |grad phi|^3 by second-order central differences, zero where |grad phi| vanishes; and the
!> volume (area in 2D, length in 1D) of phi < 0 on the interior cells,
!> V = sum (1 - H(phi)) dV with the smoothed Heaviside
!> H = 1/2 (1 + phi/eps + sin(pi phi/eps) / pi) for |phi| <= eps, eps = 1.5 max(dx).
!> Kernels read the halo (1 deep, 2 for fourth-order normals) and never fill it; the sum of
!> volumes over blocks and ranks is the caller's. No MPI, no state.
module m_levelset_geometry
  use m_kinds, only: wp
  implicit none
  private
  public :: levelset_normals, levelset_curvature, levelset_volume, levelset_heaviside
  public :: levelset_gradient_at, unit_or_zero

  real(wp), parameter :: pi = 3.14159265358979323846_wp

contains

  !> v / |v|, or 0 for v = 0.
  pure function unit_or_zero(v) result(u)
    real(wp), intent(in) :: v(3)
    real(wp) :: u(3), s
    s = norm2(v)
    u = 0.0_wp
    if (s > 0.0_wp) u = v / s
  end function unit_or_zero

  !> grad phi at cell (i, j, k) of phi (bounds lo..hi) by central differences, one-sided at
  !> the array's edge; components of unused directions zero. The ghost fill's normals
  !> (m_gfm) and levelset_normals take it.
  pure function levelset_gradient_at(ndim, dx, lo, hi, phi, i, j, k) result(grad)
    integer, intent(in) :: ndim, lo(3), hi(3), i, j, k
    real(wp), intent(in) :: dx(3)
    real(wp), intent(in) :: phi(lo(1):, lo(2):, lo(3):)
    real(wp) :: grad(3)
    integer :: a(3), b(3), d
    grad = 0.0_wp
    do d = 1, ndim
      a = [i, j, k]
      b = a
      a(d) = min(a(d) + 1, hi(d))
      b(d) = max(b(d) - 1, lo(d))
      grad(d) = (phi(a(1), a(2), a(3)) - phi(b(1), b(2), b(3))) / (real(a(d) - b(d), wp) * dx(d))
    end do
  end function levelset_gradient_at

  !> nrm(n1, n2, n3, 3): unit normals at the interior cells, components of unused
  !> directions zero; order 2 (default) or 4.
  subroutine levelset_normals(ndim, n, g, dx, phi, nrm, order)
    integer, intent(in) :: ndim, n(3), g(3)
    real(wp), intent(in) :: dx(3)
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(out) :: nrm(n(1), n(2), n(3), 3)
    integer, intent(in), optional :: order
    real(wp) :: grad(3)
    integer :: i, j, k, d, e(3), ord
    ord = 2
    if (present(order)) ord = order
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          grad = 0.0_wp
          do d = 1, ndim
            e = 0
            e(d) = 1
            if (ord == 4) then
              grad(d) = (8.0_wp * (phi(i+e(1), j+e(2), k+e(3)) - phi(i-e(1), j-e(2), k-e(3))) &
                - (phi(i+2*e(1), j+2*e(2), k+2*e(3)) - phi(i-2*e(1), j-2*e(2), k-2*e(3)))) &
                / (12.0_wp * dx(d))
            end if
          end do
          if (ord /= 4) grad = levelset_gradient_at(ndim, dx, 1 - g, n + g, phi, i, j, k)
          nrm(i, j, k, :) = unit_or_zero(grad)
        end do
      end do
    end do
  end subroutine levelset_normals

  !> kappa(n1, n2, n3) = div(grad phi / |grad phi|) at the interior cells (positive on a
  !> convex body with phi < 0 inside: 2 / R on a sphere, 1 / R on a circle).
  subroutine levelset_curvature(ndim, n, g, dx, phi, kappa)
    integer, intent(in) :: ndim, n(3), g(3)
    real(wp), intent(in) :: dx(3)
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(out) :: kappa(n(1), n(2), n(3))
    real(wp) :: grad(3), hess(3, 3), mag2, num
    integer :: i, j, k, d, q, e(3), f(3)
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          grad = 0.0_wp
          hess = 0.0_wp
          do d = 1, ndim
            e = 0
            e(d) = 1
            grad(d) = (phi(i+e(1), j+e(2), k+e(3)) - phi(i-e(1), j-e(2), k-e(3))) &
              / (2.0_wp * dx(d))
            hess(d, d) = (phi(i+e(1), j+e(2), k+e(3)) - 2.0_wp * phi(i, j, k) &
              + phi(i-e(1), j-e(2), k-e(3))) / dx(d)**2
            do q = d + 1, ndim
              f = 0
              f(q) = 1
              hess(d, q) = (phi(i+e(1)+f(1), j+e(2)+f(2), k+e(3)+f(3)) &
                - phi(i+e(1)-f(1), j+e(2)-f(2), k+e(3)-f(3)) &
                - phi(i-e(1)+f(1), j-e(2)+f(2), k-e(3)+f(3)) &
                + phi(i-e(1)-f(1), j-e(2)-f(2), k-e(3)-f(3))) / (4.0_wp * dx(d) * dx(q))
              hess(q, d) = hess(d, q)
            end do
          end do
          mag2 = sum(grad**2)
          if (mag2 > 0.0_wp) then
            num = 0.0_wp
            do d = 1, ndim
              num = num + hess(d, d) * mag2
              do q = 1, ndim
                num = num - grad(d) * grad(q) * hess(d, q)
              end do
            end do
            kappa(i, j, k) = num / mag2**1.5_wp
          else
            kappa(i, j, k) = 0.0_wp
          end if
        end do
      end do
    end do
  end subroutine levelset_curvature

  !> Smoothed Heaviside H(phi) of half width eps.
  elemental real(wp) function levelset_heaviside(phi, eps) result(h)
    real(wp), intent(in) :: phi, eps
    if (phi < -eps) then
      h = 0.0_wp
    else if (phi > eps) then
      h = 1.0_wp
    else
      h = 0.5_wp * (1.0_wp + phi / eps + sin(pi * phi / eps) / pi)
    end if
  end function levelset_heaviside

  !> vol = volume of phi < 0 over the interior cells of this block.
  subroutine levelset_volume(ndim, n, g, dx, phi, vol)
    integer, intent(in) :: ndim, n(3), g(3)
    real(wp), intent(in) :: dx(3)
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(out) :: vol
    real(wp) :: eps, s
    integer :: i, j, k
    eps = 1.5_wp * maxval(dx(1:ndim))
    s = 0.0_wp
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          s = s + (1.0_wp - levelset_heaviside(phi(i, j, k), eps))
        end do
      end do
    end do
    vol = s * product(dx(1:ndim))
  end subroutine levelset_volume

end module m_levelset_geometry
