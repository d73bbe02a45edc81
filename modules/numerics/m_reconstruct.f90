!> Reconstruction of face values from cell averages along one pencil
!> (manual/theory.md section 3): ENO of order 1, 2, 3 (Harten et al.; Shu 1997,
!> stencil chosen by the smallest undivided differences) and WENO5 (Jiang and Shu 1996,
!> eps = 1e-6). For every cell i of 0 .. n + 1 the cell's own polynomial gives the value at
!> its left face (vm) and right face (vp); face i + 1/2 then has left state vp(i) and right
!> state vm(i + 1). Variables that must stay within the range of their neighbours (plastic
!> strain, stored work: bounded_from .. nv) have their face values limited (bound_faces,
!> manual/theory.md 5.1e). Kernels only: arrays in, arrays out, no state.
module m_reconstruct
  use m_kinds, only: wp
  use m_text, only: choice_index
  implicit none
  private
  public :: scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5, scheme_from_name, scheme_names
  public :: reconstruct_faces, bound_faces, bound_weight, stencil_reach

  !> how far beyond a pencil's ends its reconstruction reads: the face values of cells
  !> 0 .. n + 1 take cells -2 .. n + 3 (ENO3, WENO5 and the characteristic transform alike)
  integer, parameter :: stencil_reach = 3

  integer, parameter :: scheme_eno1 = 1, scheme_eno2 = 2, scheme_eno3 = 3, scheme_weno5 = 5
  !> the deck's names of the schemes (&numerics scheme), in the order of scheme_codes
  character(len=5), parameter :: scheme_names(4) = [character(len=5) :: 'eno1', 'eno2', &
    'eno3', 'weno5']
  integer, parameter :: scheme_codes(4) = [scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5]
  !> the share of a cell's content given to each face value in the convex decomposition of
  !> bound_faces (the 3-point Gauss-Lobatto weight): under the condition that no face lets
  !> out more than bound_weight / ndim of a cell's mass in one stage, the upwind update of a
  !> bounded variable is a convex combination of values within its neighbours' range
  real(wp), parameter :: bound_weight = 1.0_wp / 6.0_wp

contains

  !> The scheme of a deck name (one of scheme_names).
  integer function scheme_from_name(name) result(scheme)
    character(len=*), intent(in) :: name
    scheme = scheme_codes(choice_index(scheme_names, name, 'scheme_from_name'))
  end function scheme_from_name

  !> Face states of nv variables on nb pencils of n cells with ng >= 3 halo cells, the pencil
  !> index innermost so that the loops vectorise across pencils:
  !> v(nb, 1-ng:n+ng, nv) cell averages -> left(nb, 0:n, nv), right(nb, 0:n, nv) at faces
  !> 1/2 .. n+1/2. Variables bounded_from .. nv (optional) are bounded (bound_faces). A
  !> variable that is not bounded has its cells' polynomials written straight into left and
  !> right (cells 1 .. n both, cell 0 its right face only, cell n + 1 its left face only).
  subroutine reconstruct_faces(scheme, nb, n, ng, nv, v, left, right, bounded_from)
    integer, intent(in) :: scheme, nb, n, ng, nv
    real(wp), intent(in) :: v(nb, 1-ng:n+ng, nv)
    real(wp), intent(out) :: left(nb, 0:n, nv), right(nb, 0:n, nv)
    integer, intent(in), optional :: bounded_from
    real(wp) :: vm(nb, 0:n+1), vp(nb, 0:n+1)
    integer :: m, first_bounded
    first_bounded = nv + 1
    if (present(bounded_from)) first_bounded = bounded_from
    do m = 1, nv
      if (scheme == scheme_eno1) then
        left(:, :, m) = v(:, 0:n, m)
        right(:, :, m) = v(:, 1:n+1, m)
      else if (m < first_bounded) then
        ! cell 0 (vm(:, 0) unused), cells 1 .. n, cell n + 1 (vp(:, n + 1) unused)
        call cells(0, 0, vm(:, 0), left(:, 0, m))
        if (n > 0) call cells(1, n, right(:, 0:n-1, m), left(:, 1:n, m))
        call cells(n + 1, n + 1, right(:, n, m), vp(:, n + 1))
      else
        call cells(0, n + 1, vm, vp)
        call bound_faces(nb, n, ng, v(:, :, m), vm, vp)
        left(:, :, m) = vp(:, 0:n)
        right(:, :, m) = vm(:, 1:n+1)
      end if
    end do

  contains

    !> the face values vm (left face), vp (right face) of the cells i0 .. i1 of variable m
    subroutine cells(i0, i1, cm, cp)
      integer, intent(in) :: i0, i1
      real(wp), intent(out) :: cm(nb, i0:i1), cp(nb, i0:i1)
      select case (scheme)
      case (scheme_eno2)
        call eno2(nb, n, ng, v(:, :, m), i0, i1, cm, cp)
      case (scheme_weno5)
        call weno5(nb, n, ng, v(:, :, m), i0, i1, cm, cp)
      case default
        call eno3(nb, n, ng, v(:, :, m), i0, i1, cm, cp)
      end select
    end subroutine cells

  end subroutine reconstruct_faces

  !> Limit the face values vm(i), vp(i) of each cell i = 0 .. n + 1 towards the cell value
  !> v(i) (Zhang and Shu 2010, manual/theory.md 5.1e) so that the face values and the rest
  !> v* = (v - w (vm + vp)) / (1 - 2 w) of the decomposition v = w vm + w vp + (1 - 2 w) v*
  !> (w = bound_weight) all lie within [m, M], the range of v over i - 1, i, i + 1. The
  !> scaling theta is the largest in [0, 1] that does it: 1 where the reconstruction already
  !> stays in range (smooth monotone data), 0 at a cell that is itself a local extremum.
  !> Uniform data stay uniform; a variable >= 0 keeps face values >= 0.
  subroutine bound_faces(nb, n, ng, v, vm, vp)
    integer, intent(in) :: nb, n, ng
    real(wp), intent(in) :: v(nb, 1-ng:n+ng)
    real(wp), intent(inout) :: vm(nb, 0:n+1), vp(nb, 0:n+1)
    real(wp), parameter :: w = bound_weight
    real(wp) :: lo, hi, vc, vs, theta, dmax, dmin
    integer :: i, b
    do i = 0, n + 1
      do b = 1, nb
        vc = v(b, i)
        lo = min(v(b, i-1), vc, v(b, i+1))
        hi = max(v(b, i-1), vc, v(b, i+1))
        vs = (vc - w * (vm(b, i) + vp(b, i))) / (1.0_wp - 2.0_wp * w)
        ! the largest deviations from vc above and below among vm, vp, v*
        dmax = max(vm(b, i), vp(b, i), vs) - vc
        dmin = vc - min(vm(b, i), vp(b, i), vs)
        theta = 1.0_wp
        if (dmax > hi - vc) theta = min(theta, (hi - vc) / dmax)
        if (dmin > vc - lo) theta = min(theta, (vc - lo) / dmin)
        theta = max(theta, 0.0_wp)
        ! the scaled values in [lo, hi] to the last bit (rounding of vc + theta (v - vc))
        vm(b, i) = min(max(vc + theta * (vm(b, i) - vc), lo), hi)
        vp(b, i) = min(max(vc + theta * (vp(b, i) - vc), lo), hi)
      end do
    end do
  end subroutine bound_faces

  !> ENO2: the smaller of the two one-sided slopes (no limiting to zero at extrema); on a tie
  !> their mean, so that the choice is mirror-symmetric.
  subroutine eno2(nb, n, ng, v, i0, i1, vm, vp)
    integer, intent(in) :: nb, n, ng, i0, i1
    real(wp), intent(in) :: v(nb, 1-ng:n+ng)
    real(wp), intent(out) :: vm(nb, i0:i1), vp(nb, i0:i1)
    real(wp) :: dl, dr, slope
    integer :: i, b
    do i = i0, i1
      do b = 1, nb
        dl = v(b, i) - v(b, i-1)
        dr = v(b, i+1) - v(b, i)
        ! the choice biased to each side, averaged: the same slope unless |dl| = |dr|, where
        ! it is their mean (single merges keep the loop vectorised)
        slope = 0.5_wp * (merge(dl, dr, abs(dl) < abs(dr)) + merge(dr, dl, abs(dr) < abs(dl)))
        vm(b, i) = v(b, i) - 0.5_wp * slope
        vp(b, i) = v(b, i) + 0.5_wp * slope
      end do
    end do
  end subroutine eno2

  !> ENO3: grow the stencil {i} by one cell twice, each time towards the smaller undivided
  !> difference; r = number of cells of the stencil left of i (0, 1 or 2). On a tie the two
  !> mirror-image choices are averaged, so that the result on mirrored data is the mirror
  !> image of the result.
  subroutine eno3(nb, n, ng, v, i0, i1, vm, vp)
    integer, intent(in) :: nb, n, ng, i0, i1
    real(wp), intent(in) :: v(nb, 1-ng:n+ng)
    real(wp), intent(out) :: vm(nb, i0:i1), vp(nb, i0:i1)
    real(wp), parameter :: c1 = 1.0_wp / 3.0_wp, c5 = 5.0_wp / 6.0_wp, c6 = 1.0_wp / 6.0_wp
    real(wp), parameter :: c7 = 7.0_wp / 6.0_wp, c11 = 11.0_wp / 6.0_wp
    real(wp) :: d1l, d1r, d2a, d2b, d2c, p0m, p0p, p1m, p1p, p2m, p2p
    real(wp) :: a, bb, c, d, e
    real(wp) :: tm, tp, um, up
    integer :: i, b
    do i = i0, i1
      do b = 1, nb
        a = v(b, i-2)
        bb = v(b, i-1)
        c = v(b, i)
        d = v(b, i+1)
        e = v(b, i+2)
        ! every expression is written so that its mirror image (a <-> e, bb <-> d) is the
        ! same floating-point operations: ties then break the same way on mirrored data
        d1l = abs(c - bb)
        d1r = abs(d - c)
        d2a = abs((a + c) - 2.0_wp * bb)    ! stencil {i-2, i-1, i}
        d2b = abs((bb + d) - 2.0_wp * c)    ! stencil {i-1, i, i+1}
        d2c = abs((c + e) - 2.0_wp * d)     ! stencil {i, i+1, i+2}
        p2m = (c1 * c + c5 * bb) - c6 * a
        p2p = (c11 * c - c7 * bb) + c1 * a
        p1m = (c5 * c + c1 * bb) - c6 * d
        p1p = (c5 * c + c1 * d) - c6 * bb
        p0m = (c11 * c - c7 * d) + c1 * e
        p0p = (c1 * c + c5 * d) - c6 * e
        ! the choice with ties broken to the right (tm, tp) and its mirror image with ties
        ! broken to the left (um, up), averaged: without a tie both are the same stencil and
        ! the average is exact; with a tie the result is the mirror-symmetric mean, so that
        ! mirrored data stay mirrored (two-level merges keep the loop vectorised)
        tm = merge(merge(p2m, p1m, d2a < d2b), merge(p1m, p0m, d2b < d2c), d1l < d1r)
        tp = merge(merge(p2p, p1p, d2a < d2b), merge(p1p, p0p, d2b < d2c), d1l < d1r)
        um = merge(merge(p0m, p1m, d2c < d2b), merge(p1m, p2m, d2b < d2a), d1r < d1l)
        up = merge(merge(p0p, p1p, d2c < d2b), merge(p1p, p2p, d2b < d2a), d1r < d1l)
        vm(b, i) = 0.5_wp * (tm + um)
        vp(b, i) = 0.5_wp * (tp + up)
      end do
    end do
  end subroutine eno3

  !> WENO5-JS with the ideal weights (1, 6, 3) / 10 and eps = 1e-6.
  subroutine weno5(nb, n, ng, v, i0, i1, vm, vp)
    integer, intent(in) :: nb, n, ng, i0, i1
    real(wp), intent(in) :: v(nb, 1-ng:n+ng)
    real(wp), intent(out) :: vm(nb, i0:i1), vp(nb, i0:i1)
    real(wp), parameter :: eps = 1.0e-6_wp, c13 = 13.0_wp / 12.0_wp
    real(wp) :: b0, b1, b2, a0, a1, a2, s, va, vb, vc, vd, ve
    integer :: i, b
    do i = i0, i1
      do b = 1, nb
        va = v(b, i-2)
        vb = v(b, i-1)
        vc = v(b, i)
        vd = v(b, i+1)
        ve = v(b, i+2)
        b0 = c13 * (va - 2.0_wp * vb + vc)**2 + 0.25_wp * (va - 4.0_wp * vb + 3.0_wp * vc)**2
        b1 = c13 * (vb - 2.0_wp * vc + vd)**2 + 0.25_wp * (vb - vd)**2
        b2 = c13 * (vc - 2.0_wp * vd + ve)**2 + 0.25_wp * (3.0_wp * vc - 4.0_wp * vd + ve)**2
        b0 = 1.0_wp / (eps + b0)**2
        b1 = 1.0_wp / (eps + b1)**2
        b2 = 1.0_wp / (eps + b2)**2
        ! right face i + 1/2
        a0 = 0.1_wp * b0
        a1 = 0.6_wp * b1
        a2 = 0.3_wp * b2
        s = 1.0_wp / (6.0_wp * (a0 + a1 + a2))
        vp(b, i) = s * (a0 * (2.0_wp * va - 7.0_wp * vb + 11.0_wp * vc) &
          + a1 * (-vb + 5.0_wp * vc + 2.0_wp * vd) + a2 * (2.0_wp * vc + 5.0_wp * vd - ve))
        ! left face i - 1/2: the mirror image
        a0 = 0.3_wp * b0
        a1 = 0.6_wp * b1
        a2 = 0.1_wp * b2
        s = 1.0_wp / (6.0_wp * (a0 + a1 + a2))
        vm(b, i) = s * (a0 * (-va + 5.0_wp * vb + 2.0_wp * vc) &
          + a1 * (2.0_wp * vb + 5.0_wp * vc - vd) + a2 * (11.0_wp * vc - 7.0_wp * vd + 2.0_wp * ve))
      end do
    end do
  end subroutine weno5

end module m_reconstruct
