!> A Gaussian-random-field porosity (issue 16 point 3; manual/scenes.md): white noise from
!> the scene's random numbers (m_scene_generate) on a grid of its own over a box, filtered
!> in Fourier space by FFTW (the Fortran 2003 interface, fftw3.f03) to the covariance
!> exp(-r^2 / (2 l^2)) of correlation length l, thresholded so that a chosen volume fraction
!> of the grid lies below the threshold, and turned into a signed distance to that level
!> (negative inside) by fast sweeping (Zhao 2005), which m_scene interpolates at the cells of
!> the blocks. The grid has spacing l / 8 whatever the solver's mesh, so it is small; every
!> rank builds the same one (FFTW's plan chosen by its estimate without timing and without
!> SIMD, so the same binary gives the same bits on every node): no rank talks to another.
!> The field is periodic over the box. It does not know the deck or the blocks.
module m_scene_field
  ! (all of it: the interface fftw3.f03 declares its own kinds from it)
  use, intrinsic :: iso_c_binding
  use m_kinds, only: wp
  use m_scene_generate, only: rng_t, rng_seed, rng_normal
  implicit none
  private
  public :: random_field, field_distance, field_points, max_field_points

  include 'fftw3.f03'

  !> the most grid points the generator builds (its arrays: about 40 bytes a point)
  integer, parameter :: max_field_points = 2**22
  !> grid points per correlation length
  integer, parameter :: points_per_length = 8

contains

  !> Grid points of the field along each direction for the box lo..hi and correlation
  !> length l (at least 8 along each of the first ndim directions, 1 along the others).
  pure function field_points(ndim, lo, hi, l) result(n)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: lo(3), hi(3), l
    integer :: n(3)
    n = 1
    n(1:ndim) = max(8, ceiling(points_per_length * (hi(1:ndim) - lo(1:ndim)) / l))
  end function field_points

  !> The signed distance d (negative inside) on the cell-centred grid of field_points over
  !> lo..hi to the set where the Gaussian random field of correlation length l and the
  !> random numbers of seed lies below the level that holds the fraction `fraction` of the
  !> grid points; achieved is the fraction of points inside (the nearest the grid allows).
  !> why is '' or why it could not be built.
  subroutine random_field(ndim, lo, hi, seed, l, fraction, d, achieved, why)
    integer, intent(in) :: ndim, seed
    real(wp), intent(in) :: lo(3), hi(3), l, fraction
    real(wp), allocatable, intent(out) :: d(:, :, :)
    real(wp), intent(out) :: achieved
    character(len=:), allocatable, intent(out) :: why
    type(rng_t) :: rng
    real(c_double), allocatable :: f(:, :, :)
    complex(c_double_complex), allocatable :: fk(:, :, :)
    type(c_ptr) :: plan
    integer :: n(3), i, j, k, m(3), nin
    integer(c_int) :: dims(ndim)
    real(wp) :: kk, level, h(3)
    why = ''
    achieved = 0.0_wp
    n = field_points(ndim, lo, hi, l)
    if (product(real(n, wp)) > max_field_points) then
      why = 'the field would need more than 2^22 grid points (8 per correlation length): ' &
        // 'raise correlation_length or shrink the box'
      return
    end if
    allocate(f(n(1), n(2), n(3)), fk(n(1) / 2 + 1, n(2), n(3)))
    call rng_seed(rng, seed)
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          f(i, j, k) = rng_normal(rng)
        end do
      end do
    end do
    ! FFTW is row-major: the dimensions reversed
    dims = int(n(ndim:1:-1), c_int)
    plan = fftw_plan_dft_r2c(int(ndim, c_int), dims, f, fk, ior(FFTW_ESTIMATE, FFTW_NO_SIMD))
    call fftw_execute_dft_r2c(plan, f, fk)
    call fftw_destroy_plan(plan)
    ! the Gaussian filter exp(-k^2 l^2 / 4): covariance exp(-r^2 / (2 l^2))
    h = (hi - lo) / real(n, wp)
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1) / 2 + 1
          m = [i, j, k] - 1
          where (m > n / 2) m = m - n
          kk = sum((8.0_wp * atan(1.0_wp) * m(1:ndim) / (hi(1:ndim) - lo(1:ndim)))**2)
          fk(i, j, k) = fk(i, j, k) * exp(-0.25_wp * kk * l**2)
        end do
      end do
    end do
    plan = fftw_plan_dft_c2r(int(ndim, c_int), dims, fk, f, ior(FFTW_ESTIMATE, FFTW_NO_SIMD))
    call fftw_execute_dft_c2r(plan, fk, f)
    call fftw_destroy_plan(plan)
    ! the level between the nin-th and the next value: no point lies on it
    nin = max(0, min(size(f), nint(fraction * size(f))))
    level = nth_level(f, nin)
    achieved = real(count(f < level), wp) / size(f)
    allocate(d(n(1), n(2), n(3)))
    call signed_distance(ndim, h, f - level, d)
  end subroutine random_field

  !> A level with exactly nin of the values of f below it (halfway between the nin-th and
  !> the next smallest), by bisection on the value: no sort of the whole grid.
  real(wp) function nth_level(f, nin) result(level)
    real(c_double), intent(in) :: f(:, :, :)
    integer, intent(in) :: nin
    real(wp) :: lo, hi, mid
    integer :: it
    if (nin == 0) then
      level = minval(f) - 1.0_wp
      return
    end if
    if (nin == size(f)) then
      level = maxval(f) + 1.0_wp
      return
    end if
    lo = minval(f)
    hi = maxval(f)
    do it = 1, 200   ! count(f <= hi) >= nin > count(f <= lo)
      mid = 0.5_wp * (lo + hi)
      if (.not. (mid > lo .and. mid < hi)) exit
      if (count(f <= mid) >= nin) then
        hi = mid
      else
        lo = mid
      end if
    end do
    level = 0.5_wp * (maxval(f, f <= hi) + minval(f, f > hi))
  end function nth_level

  !> Signed distance d to the zero level of g (negative where g < 0) on a grid of spacings h:
  !> the points beside a sign change start at the distance the linear crossings along the
  !> axes give, 1 / sqrt(sum 1 / d_axis^2), the rest by fast sweeping of |grad d| = 1 in the
  !> 2^ndim orderings, three rounds.
  subroutine signed_distance(ndim, h, g, d)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: h(3), g(:, :, :)
    real(wp), intent(out) :: d(:, :, :)
    integer :: n(3), i, j, k, ax, s, round, o, e(3), lo(3), hi(3), st(3), ii, jj, kk
    real(wp) :: a(3), inv, t
    logical, allocatable :: fixed(:, :, :)
    n = shape(g)
    allocate(fixed(n(1), n(2), n(3)))
    d = huge(1.0_wp)
    fixed = .false.
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          inv = 0.0_wp
          do ax = 1, ndim
            t = huge(1.0_wp)
            do s = -1, 1, 2
              e = [i, j, k]
              e(ax) = e(ax) + s
              if (e(ax) < 1 .or. e(ax) > n(ax)) cycle
              if ((g(i, j, k) < 0.0_wp) .eqv. (g(e(1), e(2), e(3)) < 0.0_wp)) cycle
              t = min(t, h(ax) * g(i, j, k) / (g(i, j, k) - g(e(1), e(2), e(3))))
            end do
            if (t < huge(1.0_wp)) inv = inv + 1.0_wp / max(t, 1.0e-12_wp * h(ax))**2
          end do
          if (inv > 0.0_wp) then
            d(i, j, k) = 1.0_wp / sqrt(inv)
            fixed(i, j, k) = .true.
          end if
        end do
      end do
    end do
    do round = 1, 3
      do o = 0, 2**ndim - 1
        do ax = 1, 3
          if (ax <= ndim .and. btest(o, ax - 1)) then
            lo(ax) = n(ax)
            hi(ax) = 1
            st(ax) = -1
          else
            lo(ax) = 1
            hi(ax) = n(ax)
            st(ax) = 1
          end if
        end do
        do kk = lo(3), hi(3), st(3)
          do jj = lo(2), hi(2), st(2)
            do ii = lo(1), hi(1), st(1)
              if (fixed(ii, jj, kk)) cycle
              do ax = 1, ndim
                e = [ii, jj, kk]
                a(ax) = huge(1.0_wp)
                if (e(ax) > 1) then
                  e(ax) = e(ax) - 1
                  a(ax) = d(e(1), e(2), e(3))
                  e(ax) = e(ax) + 1
                end if
                if (e(ax) < n(ax)) then
                  e(ax) = e(ax) + 1
                  a(ax) = min(a(ax), d(e(1), e(2), e(3)))
                end if
              end do
              d(ii, jj, kk) = min(d(ii, jj, kk), eikonal(ndim, a, h))
            end do
          end do
        end do
      end do
    end do
    d = sign(d, g)
  end subroutine signed_distance

  !> The upwind solution u of sum_axes ((u - a_axis) / h_axis)^2 = 1 over the axes whose
  !> neighbour value a is below u (the smallest first).
  pure real(wp) function eikonal(ndim, a, h) result(u)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: a(3), h(3)
    real(wp) :: s(3), w(3), p, q, r, x
    integer :: order(3), m
    logical :: taken(3)
    taken = .false.
    do m = 1, ndim   ! the axes by their neighbour value, smallest first
      order(m) = minloc(a(1:ndim), 1, .not. taken(1:ndim))
      taken(order(m)) = .true.
    end do
    s(1:ndim) = a(order(1:ndim))
    w(1:ndim) = 1.0_wp / h(order(1:ndim))**2
    u = huge(1.0_wp)
    if (.not. s(1) < huge(1.0_wp)) return
    u = s(1) + h(order(1))
    do m = 2, ndim
      if (.not. u > s(m)) exit
      p = sum(w(1:m))
      q = sum(w(1:m) * s(1:m))
      r = sum(w(1:m) * s(1:m)**2) - 1.0_wp
      x = q**2 - p * r
      if (x < 0.0_wp) exit
      u = (q + sqrt(x)) / p
    end do
  end function eikonal

  !> The field's signed distance d (on the cell-centred grid over lo..hi) at x, by
  !> multilinear interpolation (the grid's end values beyond its last centres), the body
  !> clipped by its box: max with the box's own signed distance.
  pure real(wp) function field_distance(d, ndim, lo, hi, x) result(phi)
    real(wp), intent(in) :: d(:, :, :), lo(3), hi(3), x(3)
    integer, intent(in) :: ndim
    integer :: n(3), i0(3), c, ax, idx(3)
    real(wp) :: s(3), w(3), wt
    n = shape(d)
    s = 1.0_wp
    i0 = 1
    w = 0.0_wp
    do ax = 1, ndim
      s(ax) = (x(ax) - lo(ax)) / (hi(ax) - lo(ax)) * n(ax) + 0.5_wp
      s(ax) = max(1.0_wp, min(real(n(ax), wp), s(ax)))
      i0(ax) = min(n(ax) - 1, int(s(ax)))
      if (n(ax) == 1) i0(ax) = 1
      w(ax) = s(ax) - i0(ax)
    end do
    phi = 0.0_wp
    do c = 0, 2**ndim - 1
      wt = 1.0_wp
      idx = 1
      do ax = 1, ndim
        idx(ax) = i0(ax) + merge(1, 0, btest(c, ax - 1))
        wt = wt * merge(w(ax), 1.0_wp - w(ax), btest(c, ax - 1))
      end do
      if (wt > 0.0_wp) phi = phi + wt * d(idx(1), idx(2), idx(3))
    end do
    phi = max(phi, maxval(max(lo(1:ndim) - x(1:ndim), x(1:ndim) - hi(1:ndim))))
  end function field_distance

end module m_scene_field
