!> One-sided derivatives of a level set on one block for the Hamilton-Jacobi kernels of
!> manual/theory.md section 6: HJ-ENO3 (Osher and Shu 1991) or HJ-WENO5 (Jiang and Peng 2000)
!> approximations of phi_x^- and phi_x^+ at every interior cell. Both are the ENO3 / WENO5
!> face reconstructions of m_reconstruct applied to the backward differences
!> D(j) = (phi(j) - phi(j-1)) / dx: phi_x^-(i) is the right-face value of cell i of D (stencil
!> D(i-2 .. i+2)) and phi_x^+(i) the left-face value of cell i+1 (stencil D(i-1 .. i+3)). The
!> kernel needs g >= 4 halo cells in the direction it differentiates (n_halo = 4), reads the
!> halo and never writes it; it does no MPI and keeps no state.
module m_levelset_derivatives
  use m_kinds, only: wp
  use m_reconstruct, only: reconstruct_faces
  implicit none
  private
  public :: levelset_one_sided

contains

  !> phi_x^- (dminus) and phi_x^+ (dplus) along direction dir at the n(1) x n(2) x n(3)
  !> interior cells, by scheme (scheme_eno3 or scheme_weno5 of m_reconstruct).
  subroutine levelset_one_sided(scheme, dir, n, g, dx, phi, dminus, dplus)
    integer, intent(in) :: scheme, dir, n(3), g(3)
    real(wp), intent(in) :: dx(3)
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(out) :: dminus(n(1), n(2), n(3)), dplus(n(1), n(2), n(3))
    integer, parameter :: gd = 3
    real(wp), allocatable :: v(:, :, :), left(:, :, :), right(:, :, :)
    real(wp) :: rdx
    integer :: i, j, k, nb, m
    rdx = 1.0_wp / dx(dir)
    m = n(dir)
    select case (dir)
    case (1)
      nb = n(2)
    case default
      nb = n(1)
    end select
    allocate(v(nb, 1-gd:m+gd, 1), left(nb, 0:m, 1), right(nb, 0:m, 1))
    select case (dir)
    case (1)
      do k = 1, n(3)
        do i = 1 - gd, m + gd
          do j = 1, n(2)
            v(j, i, 1) = (phi(i, j, k) - phi(i-1, j, k)) * rdx
          end do
        end do
        call reconstruct_faces(scheme, nb, m, gd, 1, v, left, right)
        do j = 1, n(2)
          do i = 1, m
            dminus(i, j, k) = left(j, i, 1)
            dplus(i, j, k) = right(j, i, 1)
          end do
        end do
      end do
    case default
      ! y or z: the lines run along the second index of a plane of phi (k or j held)
      do k = 1, n(5 - dir)
        if (dir == 2) then
          call along_plane(phi(1:n(1), :, k), dminus(:, :, k), dplus(:, :, k))
        else
          call along_plane(phi(1:n(1), k, :), dminus(:, k, :), dplus(:, k, :))
        end if
      end do
    end select

  contains

    !> One plane p(i, l) whose second index l runs along dir: its one-sided derivatives.
    subroutine along_plane(p, dm, dp)
      real(wp), intent(in) :: p(:, 1-g(dir):)
      real(wp), intent(out) :: dm(:, :), dp(:, :)
      integer :: l
      do l = 1 - gd, m + gd
        do i = 1, n(1)
          v(i, l, 1) = (p(i, l) - p(i, l-1)) * rdx
        end do
      end do
      call reconstruct_faces(scheme, nb, m, gd, 1, v, left, right)
      do l = 1, m
        do i = 1, n(1)
          dm(i, l) = left(i, l, 1)
          dp(i, l) = right(i, l, 1)
        end do
      end do
    end subroutine along_plane
  end subroutine levelset_one_sided

end module m_levelset_derivatives
