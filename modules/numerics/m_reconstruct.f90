!> Reconstruction of face values from cell averages along one pencil
!> (manual/theory.md section 3): ENO of order 1, 2, 3 (Harten et al.; Shu 1997,
!> stencil chosen by the smallest undivided differences) and WENO5 (Jiang and Shu 1996,
!> eps = 1e-6). For every cell i of 0 .. n + 1 the cell's own polynomial gives the value at
!> its left face (vm) and right face (vp); face i + 1/2 then has left state vp(i) and right
!> state vm(i + 1). Kernels only: arrays in, arrays out, no state.
module m_reconstruct
  use m_kinds, only: wp
  implicit none
  private
  public :: scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5, scheme_from_name
  public :: reconstruct_faces

  integer, parameter :: scheme_eno1 = 1, scheme_eno2 = 2, scheme_eno3 = 3, scheme_weno5 = 5

contains

  integer function scheme_from_name(name) result(scheme)
    character(len=*), intent(in) :: name
    select case (trim(name))
    case ('eno1')
      scheme = scheme_eno1
    case ('eno2')
      scheme = scheme_eno2
    case ('weno5')
      scheme = scheme_weno5
    case default
      scheme = scheme_eno3
    end select
  end function scheme_from_name

  !> Face states of nv variables on a pencil of n cells with ng >= 3 halo cells:
  !> v(1-ng:n+ng, nv) cell averages -> left(0:n, nv), right(0:n, nv) at faces 1/2 .. n+1/2.
  subroutine reconstruct_faces(scheme, n, ng, nv, v, left, right)
    integer, intent(in) :: scheme, n, ng, nv
    real(wp), intent(in) :: v(1-ng:n+ng, nv)
    real(wp), intent(out) :: left(0:n, nv), right(0:n, nv)
    real(wp) :: vm(0:n+1), vp(0:n+1)
    integer :: m
    do m = 1, nv
      select case (scheme)
      case (scheme_eno1)
        vm = v(0:n+1, m)
        vp = vm
      case (scheme_eno2)
        call eno2(n, ng, v(:, m), vm, vp)
      case (scheme_weno5)
        call weno5(n, ng, v(:, m), vm, vp)
      case default
        call eno3(n, ng, v(:, m), vm, vp)
      end select
      left(:, m) = vp(0:n)
      right(:, m) = vm(1:n+1)
    end do
  end subroutine reconstruct_faces

  !> ENO2: the smaller of the two one-sided slopes (no limiting to zero at extrema).
  subroutine eno2(n, ng, v, vm, vp)
    integer, intent(in) :: n, ng
    real(wp), intent(in) :: v(1-ng:n+ng)
    real(wp), intent(out) :: vm(0:n+1), vp(0:n+1)
    real(wp) :: dl, dr, slope
    integer :: i
    do i = 0, n + 1
      dl = v(i) - v(i-1)
      dr = v(i+1) - v(i)
      slope = merge(dl, dr, abs(dl) < abs(dr))
      vm(i) = v(i) - 0.5_wp * slope
      vp(i) = v(i) + 0.5_wp * slope
    end do
  end subroutine eno2

  !> ENO3: grow the stencil {i} by one cell twice, each time towards the smaller undivided
  !> difference; r = number of cells of the stencil left of i (0, 1 or 2).
  subroutine eno3(n, ng, v, vm, vp)
    integer, intent(in) :: n, ng
    real(wp), intent(in) :: v(1-ng:n+ng)
    real(wp), intent(out) :: vm(0:n+1), vp(0:n+1)
    real(wp), parameter :: c1 = 1.0_wp / 3.0_wp, c5 = 5.0_wp / 6.0_wp, c6 = 1.0_wp / 6.0_wp
    real(wp), parameter :: c7 = 7.0_wp / 6.0_wp, c11 = 11.0_wp / 6.0_wp
    real(wp) :: d1l, d1r, d2a, d2b, d2c, p0m, p0p, p1m, p1p, p2m, p2p
    logical :: left1, left2a, left2b
    integer :: i
    do i = 0, n + 1
      d1l = abs(v(i) - v(i-1))
      d1r = abs(v(i+1) - v(i))
      d2a = abs(v(i) - 2.0_wp * v(i-1) + v(i-2))      ! stencil {i-2, i-1, i}
      d2b = abs(v(i+1) - 2.0_wp * v(i) + v(i-1))      ! stencil {i-1, i, i+1}
      d2c = abs(v(i+2) - 2.0_wp * v(i+1) + v(i))      ! stencil {i, i+1, i+2}
      left1 = d1l < d1r
      left2a = d2a < d2b     ! from {i-1, i}: extend left?
      left2b = d2b < d2c     ! from {i, i+1}: extend left?
      p2m = -c6 * v(i-2) + c5 * v(i-1) + c1 * v(i)
      p2p = c1 * v(i-2) - c7 * v(i-1) + c11 * v(i)
      p1m = c1 * v(i-1) + c5 * v(i) - c6 * v(i+1)
      p1p = -c6 * v(i-1) + c5 * v(i) + c1 * v(i+1)
      p0m = c11 * v(i) - c7 * v(i+1) + c1 * v(i+2)
      p0p = c1 * v(i) + c5 * v(i+1) - c6 * v(i+2)
      if (left1) then
        vm(i) = merge(p2m, p1m, left2a)
        vp(i) = merge(p2p, p1p, left2a)
      else
        vm(i) = merge(p1m, p0m, left2b)
        vp(i) = merge(p1p, p0p, left2b)
      end if
    end do
  end subroutine eno3

  !> WENO5-JS with the ideal weights (1, 6, 3) / 10 and eps = 1e-6.
  subroutine weno5(n, ng, v, vm, vp)
    integer, intent(in) :: n, ng
    real(wp), intent(in) :: v(1-ng:n+ng)
    real(wp), intent(out) :: vm(0:n+1), vp(0:n+1)
    real(wp), parameter :: eps = 1.0e-6_wp, c13 = 13.0_wp / 12.0_wp
    real(wp) :: b0, b1, b2, a0, a1, a2, s
    integer :: i
    do i = 0, n + 1
      b0 = c13 * (v(i-2) - 2.0_wp * v(i-1) + v(i))**2 &
        + 0.25_wp * (v(i-2) - 4.0_wp * v(i-1) + 3.0_wp * v(i))**2
      b1 = c13 * (v(i-1) - 2.0_wp * v(i) + v(i+1))**2 + 0.25_wp * (v(i-1) - v(i+1))**2
      b2 = c13 * (v(i) - 2.0_wp * v(i+1) + v(i+2))**2 &
        + 0.25_wp * (3.0_wp * v(i) - 4.0_wp * v(i+1) + v(i+2))**2
      ! right face i + 1/2
      a0 = 0.1_wp / (eps + b0)**2
      a1 = 0.6_wp / (eps + b1)**2
      a2 = 0.3_wp / (eps + b2)**2
      s = 1.0_wp / (a0 + a1 + a2)
      vp(i) = s * (a0 * (2.0_wp * v(i-2) - 7.0_wp * v(i-1) + 11.0_wp * v(i)) &
        + a1 * (-v(i-1) + 5.0_wp * v(i) + 2.0_wp * v(i+1)) &
        + a2 * (2.0_wp * v(i) + 5.0_wp * v(i+1) - v(i+2))) / 6.0_wp
      ! left face i - 1/2: the mirror image
      a0 = 0.3_wp / (eps + b0)**2
      a1 = 0.6_wp / (eps + b1)**2
      a2 = 0.1_wp / (eps + b2)**2
      s = 1.0_wp / (a0 + a1 + a2)
      vm(i) = s * (a0 * (-v(i-2) + 5.0_wp * v(i-1) + 2.0_wp * v(i)) &
        + a1 * (2.0_wp * v(i-1) + 5.0_wp * v(i) - v(i+1)) &
        + a2 * (11.0_wp * v(i) - 7.0_wp * v(i+1) + 2.0_wp * v(i+2))) / 6.0_wp
    end do
  end subroutine weno5

end module m_reconstruct
