!> Unit test of the cut-cell geometry of m_levelset_cut (manual/theory.md section 7):
!> (1) 1D: an interval's length exact, apertures 0 or 1, one interface point at each end;
!> (2) planar cuts in 2D (nine angles, lines through grid nodes among them), in
!> axisymmetry on and off the axis, and in 3D (five normals): fractions, every face's
!> aperture and the interface vector n S against independent exact values (a strip
!> integral, a clipped chord, the inclusion-exclusion volume of a cut box) to round-off;
!> (3) in every case the discrete divergence identity sum_faces A |f| n_f + n S = 0 (with the
!> hoop term in axisymmetry) per cell, computed here from the face radii;
!> (4) a circle, a sphere and an axisymmetric sphere: the phase's area / volume and its
!> interface area converging at second order (tables printed), fractions in [0, 1],
!> cells deep inside exactly 1 with apertures 1, deep outside exactly 0, the other side
!> (-phi) complementary; (5) a level set of +-huge (a composite level set with no surface)
!> without overflow.
program test_levelset_cut
  use m_kinds, only: wp
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_error, check_done, int_text
  use m_levelset_cut, only: levelset_cut, levelset_cut_volume
  implicit none
  real(wp), parameter :: pi = 3.14159265358979323846_wp, two_pi = 2.0_wp * pi
  integer, parameter :: ng = 2        !< halo of the test's level sets (the kernel needs 1)

  !> One block's cut-cell geometry
  type :: cut_t
    real(wp), allocatable :: ax(:, :, :), ay(:, :, :), az(:, :, :), alpha(:, :, :)
    real(wp), allocatable :: area(:, :, :), normal(:, :, :, :), plane(:, :, :)
  end type cut_t

  call comm_init()
  call check_start('test_levelset_cut', show_passes=.true.)
  call check_1d()
  call check_planar_2d(.false., -0.4_wp)
  call check_planar_2d(.true., 0.0_wp)
  call check_planar_2d(.true., 0.55_wp)
  call check_planar_3d()
  call check_huge()
  call sphere_study('circle R = 0.6 (area pi R^2, length 2 pi R)', 2, .false., &
    [16, 32, 64, 128, 256], 1.0e-4_wp)
  call sphere_study('sphere R = 0.6 (volume 4/3 pi R^3, area 4 pi R^2)', 3, .false., &
    [8, 16, 32, 64], 5.0e-3_wp)
  call sphere_study('axisymmetric sphere R = 0.6 (r-z disc, 2 n cells along z)', 2, .true., &
    [16, 32, 64, 128, 256], 1.0e-4_wp)
  call check_done()

contains

  subroutine compute(ndim, axi, n, dx, r0, phi, c)
    integer, intent(in) :: ndim, n(3)
    logical, intent(in) :: axi
    real(wp), intent(in) :: dx(3), r0
    real(wp), intent(in) :: phi(:, :, :)
    type(cut_t), intent(out) :: c
    integer :: g(3)
    g = merge(ng, 0, [1, 2, 3] <= ndim)
    allocate(c%ax(0:n(1), n(2), n(3)), c%ay(n(1), 0:n(2), n(3)), c%az(n(1), n(2), 0:n(3)))
    allocate(c%alpha(n(1), n(2), n(3)), c%area(n(1), n(2), n(3)), c%normal(n(1), n(2), n(3), 3))
    allocate(c%plane(n(1), n(2), n(3)))
    call levelset_cut(ndim, axi, n, g, dx, r0, phi, c%ax, c%ay, c%az, c%alpha, c%area, &
      c%normal, c%plane)
  end subroutine compute

  !> Largest |sum_faces A |f| n_f + n S - hoop| per cell over the largest face of the cell.
  real(wp) function identity_error(ndim, axi, n, dx, r0, c) result(err)
    integer, intent(in) :: ndim, n(3)
    logical, intent(in) :: axi
    real(wp), intent(in) :: dx(3), r0
    type(cut_t), intent(in) :: c
    real(wp) :: f(3), res(3), rm, rp, rc, scale
    integer :: i, j, k
    f = 1.0_wp
    if (ndim == 2) f(1:2) = [dx(2), dx(1)]
    if (ndim == 3) f = [dx(2) * dx(3), dx(1) * dx(3), dx(1) * dx(2)]
    err = 0.0_wp
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          res = c%area(i, j, k) * c%normal(i, j, k, :)
          res(1) = res(1) + (c%ax(i, j, k) - c%ax(i-1, j, k)) * f(1)
          if (ndim >= 2) res(2) = res(2) + (c%ay(i, j, k) - c%ay(i, j-1, k)) * f(2)
          if (ndim == 3) res(3) = res(3) + (c%az(i, j, k) - c%az(i, j, k-1)) * f(3)
          scale = maxval(f)
          if (axi) then
            rm = r0 + real(i - 1, wp) * dx(1)
            rp = r0 + real(i, wp) * dx(1)
            rc = r0 + (real(i, wp) - 0.5_wp) * dx(1)
            res(1) = c%area(i, j, k) * c%normal(i, j, k, 1) + two_pi * dx(2) &
              * (c%ax(i, j, k) * rp - c%ax(i-1, j, k) * rm) &
              - two_pi * c%plane(i, j, k) * dx(1) * dx(2)
            res(2) = c%area(i, j, k) * c%normal(i, j, k, 2) + two_pi * rc * dx(1) &
              * (c%ay(i, j, k) - c%ay(i, j-1, k))
            scale = two_pi * max(rp * dx(2), rc * dx(1))
          end if
          err = max(err, maxval(abs(res)) / scale)
        end do
      end do
    end do
  end function identity_error

  !> Fractions and apertures in [0, 1] (NaN fails).
  logical function in_unit_range(c) result(ok)
    type(cut_t), intent(in) :: c
    ok = all(c%alpha >= 0.0_wp .and. c%alpha <= 1.0_wp) &
      .and. all(c%ax >= 0.0_wp .and. c%ax <= 1.0_wp) &
      .and. all(c%ay >= 0.0_wp .and. c%ay <= 1.0_wp) &
      .and. all(c%az >= 0.0_wp .and. c%az <= 1.0_wp) .and. all(c%area >= 0.0_wp)
  end function in_unit_range

  !> x equal to v (a NaN is equal to nothing)
  elemental logical function same(x, v)
    real(wp), intent(in) :: x, v
    same = x >= v .and. x <= v
  end function same

  ! ---- exact values for a half-space n . x < d ----------------------------------------

  !> The part [lo, hi] of [u0, u1] where a + b u < 0 (lo = hi = u0 when empty).
  pure subroutine wet_part(a, b, u0, u1, lo, hi)
    real(wp), intent(in) :: a, b, u0, u1
    real(wp), intent(out) :: lo, hi
    real(wp) :: root
    lo = u0
    hi = u1
    if (.not. abs(b) > 0.0_wp) then
      if (.not. a < 0.0_wp) hi = u0
      return
    end if
    root = -a / b
    if (b > 0.0_wp) then
      hi = min(u1, max(u0, root))
    else
      lo = max(u0, min(u1, root))
    end if
  end subroutine wet_part

  !> int int x^kx dA over the box [xl, xh] cut by nv . x < d (2D): a strip integral along
  !> the direction of the smaller normal component, split where the cut meets a side,
  !> Simpson's rule on each piece (exact: the integrand is at most quadratic there).
  real(wp) function half_plane_moment(nv, d, xl, xh, kx) result(s)
    real(wp), intent(in) :: nv(2), d, xl(2), xh(2)
    integer, intent(in) :: kx
    real(wp) :: br(4), t, a, b
    integer :: sdir, tdir, nb, m, q
    sdir = 1
    if (abs(nv(1)) > abs(nv(2))) sdir = 2
    tdir = 3 - sdir
    br(1) = xl(sdir)
    nb = 1
    if (abs(nv(sdir)) > 0.0_wp) then
      do m = 1, 2
        t = (d - nv(tdir) * merge(xl(tdir), xh(tdir), m == 1)) / nv(sdir)
        if (t > xl(sdir) .and. t < xh(sdir)) then
          nb = nb + 1
          br(nb) = t
        end if
      end do
    end if
    nb = nb + 1
    br(nb) = xh(sdir)
    ! sort the (at most two) inner break points
    if (nb == 4) then
      if (br(2) > br(3)) br(2:3) = [br(3), br(2)]
    end if
    s = 0.0_wp
    do q = 1, nb - 1
      a = br(q)
      b = br(q + 1)
      s = s + (b - a) / 6.0_wp * (strip(nv, d, xl, xh, kx, sdir, a) &
        + 4.0_wp * strip(nv, d, xl, xh, kx, sdir, 0.5_wp * (a + b)) &
        + strip(nv, d, xl, xh, kx, sdir, b))
    end do
  end function half_plane_moment

  !> The integrand of half_plane_moment at x_sdir = u: int x^kx over the wet part of the
  !> line across the box.
  real(wp) function strip(nv, d, xl, xh, kx, sdir, u) result(w)
    real(wp), intent(in) :: nv(2), d, xl(2), xh(2), u
    integer, intent(in) :: kx, sdir
    real(wp) :: lo, hi
    integer :: tdir
    tdir = 3 - sdir
    call wet_part(nv(sdir) * u - d, nv(tdir), xl(tdir), xh(tdir), lo, hi)
    if (tdir == 1) then
      w = (hi**(kx + 1) - lo**(kx + 1)) / real(kx + 1, wp)
    else
      w = u**kx * (hi - lo)
    end if
  end function strip

  !> The chord of the line nv . x = d inside the box [xl, xh] (Liang-Barsky): its length
  !> and the x of its midpoint.
  pure subroutine chord(nv, d, xl, xh, length, xmid)
    real(wp), intent(in) :: nv(2), d, xl(2), xh(2)
    real(wp), intent(out) :: length, xmid
    real(wp) :: tau(2), p0(2), slo, shi, a, b
    integer :: m
    tau = [-nv(2), nv(1)]
    p0 = d * nv
    slo = -huge(1.0_wp)
    shi = huge(1.0_wp)
    do m = 1, 2
      if (abs(tau(m)) > 0.0_wp) then
        a = (xl(m) - p0(m)) / tau(m)
        b = (xh(m) - p0(m)) / tau(m)
        slo = max(slo, min(a, b))
        shi = min(shi, max(a, b))
      else if (p0(m) < xl(m) .or. p0(m) > xh(m)) then
        shi = slo
      end if
    end do
    length = max(0.0_wp, shi - slo)
    xmid = p0(1) + 0.5_wp * (slo + shi) * tau(1)
    if (.not. length > 0.0_wp) xmid = 0.0_wp
  end subroutine chord

  !> Measure of the part m . xi < e of the unit box of dimension size(m) (2 or 3) by
  !> inclusion-exclusion over its corners v (m_i /= 0):
  !> V = sum_v (-1)^|v| max(0, e - m . v)^dim / (dim! prod |m_i|), and its derivative in e
  !> (the measure of the cut in these coordinates).
  pure subroutine box_exact(m, e, v, dv)
    real(wp), intent(in) :: m(:), e
    real(wp), intent(out) :: v, dv
    real(wp) :: ee, t, sgn, fact
    integer :: q, b, nd, corner(size(m))
    nd = size(m)
    ee = e - sum(min(m, 0.0_wp))
    v = 0.0_wp
    dv = 0.0_wp
    do q = 0, 2**nd - 1
      do b = 1, nd
        corner(b) = ibits(q, b - 1, 1)
      end do
      t = max(0.0_wp, ee - dot_product(abs(m), real(corner, wp)))
      sgn = (-1.0_wp)**sum(corner)
      v = v + sgn * t**nd
      dv = dv + sgn * real(nd, wp) * t**(nd - 1)
    end do
    fact = merge(2.0_wp, 6.0_wp, nd == 2) * product(abs(m))
    v = v / fact
    dv = dv / fact
  end subroutine box_exact

  ! ---- the checks --------------------------------------------------------------------

  subroutine check_1d()
    integer, parameter :: m = 40
    real(wp), parameter :: cx = 0.4871_wp, r = 0.2113_wp
    real(wp) :: phi(1-ng:m+ng, 1, 1), dx(3), x, len
    type(cut_t) :: c
    integer :: i
    dx = [1.0_wp / m, 1.0_wp, 1.0_wp]
    do i = 1 - ng, m + ng
      x = (real(i, wp) - 0.5_wp) * dx(1)
      phi(i, 1, 1) = abs(x - cx) - r
    end do
    call compute(1, .false., [m, 1, 1], dx, 0.0_wp, phi, c)
    len = levelset_cut_volume(1, .false., [m, 1, 1], dx, 0.0_wp, c%alpha)
    write(6, '(a,es10.3)') '  1D interval: length error ', abs(len - 2.0_wp * r)
    call check_error('1D interval length exact', abs(len - 2.0_wp * r), 1.0e-14_wp)
    call check('1D apertures 0 or 1', all(same(c%ax, 0.0_wp) .or. same(c%ax, 1.0_wp)))
    call check('1D one interface point at each end', count(c%area > 0.0_wp) == 2 &
      .and. all(same(c%area, 0.0_wp) .or. same(c%area, 1.0_wp)) &
      .and. same(minval(c%normal(:, 1, 1, 1)), -1.0_wp) &
      .and. same(maxval(c%normal(:, 1, 1, 1)), 1.0_wp))
    call check('1D fractions in [0, 1]', in_unit_range(c))
    call check_error('1D divergence identity', &
      identity_error(1, .false., [m, 1, 1], dx, 0.0_wp, c), 1.0e-14_wp)
  end subroutine check_1d

  !> Straight cuts of a 12 x 9 block of cells 0.1 x 0.07 whose low x face is at r0 (x = r
  !> in axisymmetry), z from -0.3: nine normals, two lines each; the last two lines run
  !> along the cells' diagonals through grid nodes.
  subroutine check_planar_2d(axi, r0)
    logical, intent(in) :: axi
    real(wp), intent(in) :: r0
    integer, parameter :: n(3) = [12, 9, 1]
    real(wp), parameter :: deg(9) = [0.0_wp, 90.0_wp, 30.0_wp, 45.0_wp, 60.0_wp, &
      123.4_wp, 200.0_wp, 271.0_wp, 333.3_wp]
    real(wp) :: phi(1-ng:n(1)+ng, 1-ng:n(2)+ng, 1), dx(3), lo(2), nv(2), p(2), d
    real(wp) :: xl(2), xh(2), e_frac, e_plane, e_ap, e_vec, e_id, ex, ep, vol, len, xm
    real(wp) :: svec(2), scale, wlo, whi
    type(cut_t) :: c
    integer :: a, b, i, j, ncase
    character(len=40) :: tag
    dx = [0.1_wp, 0.07_wp, 1.0_wp]
    lo = [r0, -0.3_wp]
    e_frac = 0.0_wp
    e_plane = 0.0_wp
    e_ap = 0.0_wp
    e_vec = 0.0_wp
    e_id = 0.0_wp
    ncase = 0
    do a = 1, size(deg) + 1
      do b = 1, 2
        if (a <= size(deg)) then
          nv = [cos(deg(min(a, size(deg))) * pi / 180.0_wp), &
            sin(deg(min(a, size(deg))) * pi / 180.0_wp)]
          p = lo + merge([0.5137_wp, 0.4711_wp], [0.2377_wp, 0.8123_wp], b == 1) &
            * real(n(1:2), wp) * dx(1:2)
        else
          ! along the cell diagonals, through the nodes (x_3, y_2) and (x_7, y_4)
          nv = [-dx(2), dx(1)] / norm2(dx(1:2))
          p = lo + merge([3.0_wp, 2.0_wp], [7.0_wp, 4.0_wp], b == 1) * dx(1:2)
        end if
        d = dot_product(nv, p)
        ncase = ncase + 1
        do j = 1 - ng, n(2) + ng
          do i = 1 - ng, n(1) + ng
            phi(i, j, 1) = dot_product(nv, lo + ([i, j] - 0.5_wp) * dx(1:2)) - d
          end do
        end do
        call compute(2, axi, n, dx, r0, phi, c)
        e_id = max(e_id, identity_error(2, axi, n, dx, r0, c))
        do j = 1, n(2)
          do i = 1, n(1)
            xl = lo + ([i, j] - 1) * dx(1:2)
            xh = xl + dx(1:2)
            vol = half_plane_moment(nv, d, xl, xh, 0) / product(dx(1:2))
            ex = vol
            if (axi) ex = half_plane_moment(nv, d, xl, xh, 1) &
              / (product(dx(1:2)) * 0.5_wp * (xl(1) + xh(1)))
            e_frac = max(e_frac, abs(c%alpha(i, j, 1) - ex))
            e_plane = max(e_plane, abs(c%plane(i, j, 1) - vol))
            ! the x faces x = xl(1), xh(1) and the y faces y = xl(2), xh(2) of this cell
            call wet_part(nv(1) * xl(1) - d, nv(2), xl(2), xh(2), wlo, whi)
            e_ap = max(e_ap, abs(c%ax(i-1, j, 1) - (whi - wlo) / dx(2)))
            call wet_part(nv(1) * xh(1) - d, nv(2), xl(2), xh(2), wlo, whi)
            e_ap = max(e_ap, abs(c%ax(i, j, 1) - (whi - wlo) / dx(2)))
            call wet_part(nv(2) * xl(2) - d, nv(1), xl(1), xh(1), wlo, whi)
            ep = (whi - wlo) / dx(1)
            if (axi) ep = (whi**2 - wlo**2) / (dx(1) * (xl(1) + xh(1)))
            e_ap = max(e_ap, abs(c%ay(i, j-1, 1) - ep))
            call wet_part(nv(2) * xh(2) - d, nv(1), xl(1), xh(1), wlo, whi)
            ep = (whi - wlo) / dx(1)
            if (axi) ep = (whi**2 - wlo**2) / (dx(1) * (xl(1) + xh(1)))
            e_ap = max(e_ap, abs(c%ay(i, j, 1) - ep))
            call chord(nv, d, xl, xh, len, xm)
            svec = len * nv
            scale = maxval(dx(1:2))
            if (axi) then
              svec = two_pi * xm * svec
              scale = two_pi * xh(1) * scale
            end if
            e_vec = max(e_vec, maxval(abs(c%area(i, j, 1) * c%normal(i, j, 1, 1:2) - svec)) &
              / scale)
          end do
        end do
        if (.not. in_unit_range(c)) e_frac = huge(1.0_wp)
      end do
    end do
    if (axi) then
      write(tag, '(a,f4.2,a)') 'axisymmetric, r0 = ', r0, ':'
    else
      tag = '2D:'
    end if
    write(6, '(a,i0,a,4es10.2)') '  planar ' // trim(tag) // ' ', ncase, &
      ' lines, worst fraction, aperture, n S, identity ', e_frac, e_ap, e_vec, e_id
    call check_error('planar ' // trim(tag) // ' fractions exact', e_frac, 1.0e-13_wp)
    if (axi) call check_error('planar ' // trim(tag) // ' planar fractions exact', e_plane, &
      1.0e-13_wp)
    call check_error('planar ' // trim(tag) // ' apertures exact', e_ap, 1.0e-13_wp)
    call check_error('planar ' // trim(tag) // ' interface n S exact', e_vec, 1.0e-13_wp)
    call check_error('planar ' // trim(tag) // ' divergence identity', e_id, 1.0e-14_wp)
  end subroutine check_planar_2d

  !> Planes with five normals (no component zero, so that the inclusion-exclusion volumes
  !> apply), two points each, through a 6 x 5 x 4 block of cells 0.1 x 0.08 x 0.12.
  subroutine check_planar_3d()
    integer, parameter :: n(3) = [6, 5, 4]
    real(wp), parameter :: normals(3, 5) = reshape([1.0_wp, 2.0_wp, 3.0_wp, &
      -1.0_wp, 0.7_wp, 0.4_wp, 0.3_wp, -0.9_wp, -0.5_wp, -0.6_wp, -0.6_wp, 0.53_wp, &
      0.25_wp, 0.2_wp, -1.0_wp], [3, 5])
    real(wp) :: phi(1-ng:n(1)+ng, 1-ng:n(2)+ng, 1-ng:n(3)+ng), dx(3), lo(3), nv(3), p(3), d
    real(wp) :: xl(3), e_frac, e_ap, e_vec, e_id, v, dv, ap, dap, fa(3), svec(3)
    type(cut_t) :: c
    integer :: a, b, i, j, k, ncase
    dx = [0.1_wp, 0.08_wp, 0.12_wp]
    lo = [-0.3_wp, 0.1_wp, -0.2_wp]
    fa = [dx(2) * dx(3), dx(1) * dx(3), dx(1) * dx(2)]
    e_frac = 0.0_wp
    e_ap = 0.0_wp
    e_vec = 0.0_wp
    e_id = 0.0_wp
    ncase = 0
    do a = 1, size(normals, 2)
      do b = 1, 2
        nv = normals(:, a) / norm2(normals(:, a))
        p = lo + merge([0.51_wp, 0.47_wp, 0.53_wp], [0.31_wp, 0.62_wp, 0.44_wp], b == 1) &
          * real(n, wp) * dx
        d = dot_product(nv, p)
        ncase = ncase + 1
        do k = 1 - ng, n(3) + ng
          do j = 1 - ng, n(2) + ng
            do i = 1 - ng, n(1) + ng
              phi(i, j, k) = dot_product(nv, lo + ([i, j, k] - 0.5_wp) * dx) - d
            end do
          end do
        end do
        call compute(3, .false., n, dx, 0.0_wp, phi, c)
        e_id = max(e_id, identity_error(3, .false., n, dx, 0.0_wp, c))
        do k = 1, n(3)
          do j = 1, n(2)
            do i = 1, n(1)
              xl = lo + ([i, j, k] - 1) * dx
              call box_exact(nv * dx, d - dot_product(nv, xl), v, dv)
              e_frac = max(e_frac, abs(c%alpha(i, j, k) - v))
              svec = product(dx) * dv * nv
              e_vec = max(e_vec, maxval(abs(c%area(i, j, k) * c%normal(i, j, k, :) - svec)) &
                / maxval(fa))
              ! the low face of each direction (the high ones are the next cell's low faces,
              ! and the block's last faces are checked with the shifted origin below)
              call box_exact(nv(2:3) * dx(2:3), d - dot_product(nv, xl), ap, dap)
              e_ap = max(e_ap, abs(c%ax(i-1, j, k) - ap))
              call box_exact(nv(2:3) * dx(2:3), d - dot_product(nv, xl) - nv(1) * dx(1), &
                ap, dap)
              e_ap = max(e_ap, abs(c%ax(i, j, k) - ap))
              call box_exact(nv([1, 3]) * dx([1, 3]), d - dot_product(nv, xl), ap, dap)
              e_ap = max(e_ap, abs(c%ay(i, j-1, k) - ap))
              call box_exact(nv([1, 3]) * dx([1, 3]), d - dot_product(nv, xl) &
                - nv(2) * dx(2), ap, dap)
              e_ap = max(e_ap, abs(c%ay(i, j, k) - ap))
              call box_exact(nv(1:2) * dx(1:2), d - dot_product(nv, xl), ap, dap)
              e_ap = max(e_ap, abs(c%az(i, j, k-1) - ap))
              call box_exact(nv(1:2) * dx(1:2), d - dot_product(nv, xl) - nv(3) * dx(3), &
                ap, dap)
              e_ap = max(e_ap, abs(c%az(i, j, k) - ap))
            end do
          end do
        end do
        if (.not. in_unit_range(c)) e_frac = huge(1.0_wp)
      end do
    end do
    write(6, '(a,i0,a,4es10.2)') '  planar 3D: ', ncase, &
      ' planes, worst fraction, aperture, n S, identity ', e_frac, e_ap, e_vec, e_id
    call check_error('planar 3D fractions exact', e_frac, 1.0e-12_wp)
    call check_error('planar 3D apertures exact', e_ap, 1.0e-12_wp)
    call check_error('planar 3D interface n S exact', e_vec, 1.0e-12_wp)
    call check_error('planar 3D divergence identity', e_id, 1.0e-14_wp)
  end subroutine check_planar_3d

  !> The composite level set of a phase with no surface near is +-huge (m_levelset_bodies):
  !> no overflow, the fractions 1 and 0 on either side of a jump from -huge to huge.
  subroutine check_huge()
    integer, parameter :: n(3) = [6, 4, 1]
    real(wp) :: phi(1-ng:n(1)+ng, 1-ng:n(2)+ng, 1)
    type(cut_t) :: c
    phi = -huge(1.0_wp)
    phi(4:, :, :) = huge(1.0_wp)
    call compute(2, .false., n, [0.1_wp, 0.1_wp, 1.0_wp], 0.0_wp, phi, c)
    call check('+-huge level set: fractions 1 inside, 0 outside, in [0, 1]', &
      in_unit_range(c) .and. all(same(c%alpha(1:2, :, 1), 1.0_wp)) &
      .and. all(same(c%alpha(5:6, :, 1), 0.0_wp)))
  end subroutine check_huge

  !> Checks shared by the curved shapes: range, exact 1 and 0 away from the surface (and
  !> apertures 1 around a cell deep inside), the identity, the complement's geometry.
  subroutine check_curved(what, ndim, axi, n, dx, r0, phi, c, h)
    character(len=*), intent(in) :: what
    integer, intent(in) :: ndim, n(3)
    logical, intent(in) :: axi
    real(wp), intent(in) :: dx(3), r0, h
    real(wp), intent(in) :: phi(:, :, :)
    type(cut_t), intent(in) :: c
    type(cut_t) :: o
    logical :: ok
    real(wp) :: err, scale
    integer :: i, j, k, d, g(3)
    g = merge(ng, 0, [1, 2, 3] <= ndim)
    ok = in_unit_range(c)
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          associate (p => phi(i + g(1), j + g(2), k + g(3)))
            if (p < -2.0_wp * h) ok = ok .and. same(c%alpha(i, j, k), 1.0_wp) &
              .and. same(c%ax(i-1, j, k), 1.0_wp) .and. same(c%ax(i, j, k), 1.0_wp) &
              .and. same(c%ay(i, j-1, k), 1.0_wp) .and. same(c%ay(i, j, k), 1.0_wp) &
              .and. same(c%az(i, j, k-1), 1.0_wp) .and. same(c%az(i, j, k), 1.0_wp) &
              .and. same(c%area(i, j, k), 0.0_wp)
            if (p > 2.0_wp * h) ok = ok .and. same(c%alpha(i, j, k), 0.0_wp) &
              .and. same(c%area(i, j, k), 0.0_wp)
          end associate
        end do
      end do
    end do
    call check(what // ': fractions in [0, 1], 1 inside, 0 outside', ok)
    call check_error(what // ': divergence identity', &
      identity_error(ndim, axi, n, dx, r0, c), 1.0e-13_wp)
    ! the other side (-phi, the partner phase of a material interface) has the complementary
    ! fractions and apertures and the opposite n S: what one phase loses the other can gain
    call compute(ndim, axi, n, dx, r0, -phi, o)
    err = max(maxval(abs(c%alpha + o%alpha - 1.0_wp)), maxval(abs(c%ax + o%ax - 1.0_wp)), &
      maxval(abs(c%ay + o%ay - 1.0_wp)), maxval(abs(c%az + o%az - 1.0_wp)))
    scale = maxval(c%area)
    do d = 1, 3
      err = max(err, maxval(abs(c%area * c%normal(:, :, :, d) + o%area * o%normal(:, :, :, d))) &
        / scale)
    end do
    call check_error(what // ': the other side complementary', err, 1.0e-13_wp)
  end subroutine check_curved

  !> The table of a convergence study, and its checks: the observed order of the last
  !> refinement of the enclosed measure at least 1.8, its error at the finest grid below
  !> tol; the interface area's order is printed.
  subroutine convergence(what, cells, err_vol, err_area, tol)
    character(len=*), intent(in) :: what
    integer, intent(in) :: cells(:)
    real(wp), intent(in) :: err_vol(:), err_area(:), tol
    integer :: m, nm
    real(wp) :: ov, oa
    nm = size(cells)
    write(6, '(a)') '  ' // what // ': cells  |volume error|  order  |area error|  order'
    write(6, '(a,i6,es14.3,7x,es14.3)') '  ', cells(1), err_vol(1), err_area(1)
    do m = 2, nm
      ov = log(err_vol(m - 1) / err_vol(m)) / log(real(cells(m), wp) / cells(m - 1))
      oa = log(err_area(m - 1) / err_area(m)) / log(real(cells(m), wp) / cells(m - 1))
      write(6, '(a,i6,es14.3,f7.2,es14.3,f7.2)') '  ', cells(m), err_vol(m), ov, &
        err_area(m), oa
    end do
    ov = log(err_vol(nm - 1) / err_vol(nm)) / log(real(cells(nm), wp) / cells(nm - 1))
    call check_error(what // ': volume error at the finest grid', err_vol(nm), tol)
    call check_error(what // ': volume order of the last refinement >= 1.8', 1.8_wp - ov, &
      0.0_wp, shown=ov)
  end subroutine convergence

  !> A circle (ndim 2), a sphere (ndim 3) or a sphere on the axis as a disc in r-z (axi:
  !> r in [0, 1] with n cells, z in [-1, 1] with 2 n) of radius 0.6, its centre off the grid's
  !> symmetry lines, at each size of cells: the enclosed measure and the interface area
  !> against the exact ones; range and identity checks at the coarsest and finest grid.
  subroutine sphere_study(what, ndim, axi, sizes, tol)
    character(len=*), intent(in) :: what
    integer, intent(in) :: ndim, sizes(:)
    logical, intent(in) :: axi
    real(wp), intent(in) :: tol
    real(wp), parameter :: r = 0.6_wp
    real(wp) :: ev(size(sizes)), ea(size(sizes)), dx(3), lo(3), x(3), ctr(3), vol, surf
    real(wp), allocatable :: phi(:, :, :)
    type(cut_t) :: c
    integer :: m, i, j, k, n(3), g(3)
    character(len=:), allocatable :: grid
    ctr = [0.031_wp, -0.017_wp, 0.011_wp]
    lo = -1.0_wp
    if (axi) then
      ctr = [0.0_wp, 0.0213_wp, 0.0_wp]
      lo(1) = 0.0_wp
    end if
    vol = 4.0_wp / 3.0_wp * pi * r**3
    surf = 4.0_wp * pi * r**2
    if (ndim == 2 .and. .not. axi) then
      vol = pi * r**2
      surf = two_pi * r
    end if
    g = merge(ng, 0, [1, 2, 3] <= ndim)
    do m = 1, size(sizes)
      n = 1
      n(1:ndim) = sizes(m)
      if (axi) n(2) = 2 * sizes(m)
      dx = 1.0_wp
      dx(1:ndim) = 2.0_wp / n(1:ndim)
      if (axi) dx(1) = 1.0_wp / n(1)
      allocate(phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3)))
      do k = 1 - g(3), n(3) + g(3)
        do j = 1 - g(2), n(2) + g(2)
          do i = 1 - g(1), n(1) + g(1)
            x = lo + ([i, j, k] - 0.5_wp) * dx
            phi(i, j, k) = norm2(x(1:ndim) - ctr(1:ndim)) - r
          end do
        end do
      end do
      call compute(ndim, axi, n, dx, lo(1), phi, c)
      ev(m) = abs(levelset_cut_volume(ndim, axi, n, dx, lo(1), c%alpha) - vol)
      ea(m) = abs(sum(c%area) - surf)
      grid = int_text(n(1)) // ' x ' // int_text(n(2))
      if (ndim == 3) grid = grid // ' x ' // int_text(n(3))
      if (m == 1 .or. m == size(sizes)) call check_curved(what // ' ' // grid, ndim, axi, &
        n, dx, lo(1), phi, c, norm2(dx(1:ndim)))
      deallocate(phi)
    end do
    call convergence(what, sizes, ev, ea, tol)
  end subroutine sphere_study

end program test_levelset_cut
