!> Probes of the ghost-fluid method (DESIGN section 1, manual/interfaces.md section 3): the
!> value of the primitive variables at an image point inside the material, from the real
!> cells around it. Points are given in cell-index coordinates (cell i has its centre at
!> s = i; an inactive direction has lo = hi = 1 and s = 1).
!> - probe_trilinear: (bi/tri)linear interpolation over the 2^ndim cells around the point.
!>   The stencil is complete when all of them are real and inside the array; an incomplete
!>   stencil still gives a value (from the cells it has, real or not) and says so.
!> - probe_least_squares: a linear fit a0 + a . (x - s), weighted 1 / (1 + d^2) (d the
!>   distance in cells), over the real cells among the 3^ndim nearest, or the 5^ndim nearest
!>   where those do not determine the fit; with fewer than ndim + 1 such cells (or a
!>   singular fit) the mean of the real cells within two cells (npts < 0 then: minus their
!>   number); npts = 0 when there is none. Variables bounded_from .. (optional; plastic
!>   strain, stored work) are kept within the range of the real cells of the fit: a linear
!>   fit extrapolates, and a ghost that turns real would start outside that range (a
!>   negative plastic strain at the foot of the Taylor bar).
!> - probe_scalar, deepest_on_ray: one field (a composite level set) at a point, bilinear
!>   (trilinear in 3D), and the point of a ray where it is least: where an image point lies
!>   beyond a region thinner than its distance (m_gfm's fill_phase).
!> Kernels only.
module m_gfm_probe
  use m_kinds, only: wp
  use m_state, only: n_solid
  implicit none
  private
  public :: probe_trilinear, probe_least_squares, probe_scalar, deepest_on_ray

  integer, parameter :: max_var = n_solid + 1   !< a solid phase's variables and its reaction

contains

  subroutine probe_trilinear(ndim, lo, hi, w, isreal, s, val, complete)
    integer, intent(in) :: ndim, lo(3), hi(3)
    real(wp), intent(in) :: w(lo(1):, lo(2):, lo(3):, :)
    logical, intent(in) :: isreal(lo(1):, lo(2):, lo(3):)
    real(wp), intent(in) :: s(3)
    real(wp), intent(out) :: val(:)
    logical, intent(out) :: complete
    integer :: c(3, 8), a, i0(3)
    real(wp) :: wt(8)
    call corners(ndim, lo, hi, s, i0, c, wt)
    complete = all(floor(s(1:ndim)) == i0(1:ndim))
    val = 0.0_wp
    do a = 1, 2**ndim
      complete = complete .and. isreal(c(1, a), c(2, a), c(3, a))
      val = val + wt(a) * w(c(1, a), c(2, a), c(3, a), :)
    end do
  end subroutine probe_trilinear

  !> The 2^ndim cells around the point s (cell index coordinates), the nearest inside
  !> lo..hi, and their bilinear (trilinear) weights; i0 the first cell.
  pure subroutine corners(ndim, lo, hi, s, i0, c, wt)
    integer, intent(in) :: ndim, lo(3), hi(3)
    real(wp), intent(in) :: s(3)
    integer, intent(out) :: i0(3), c(3, 8)
    real(wp), intent(out) :: wt(8)
    integer :: a, b, d
    real(wp) :: f(3)
    i0 = 1
    f = 0.0_wp
    do d = 1, ndim
      i0(d) = min(max(floor(s(d)), lo(d)), hi(d) - 1)
      f(d) = min(max(s(d) - real(i0(d), wp), 0.0_wp), 1.0_wp)
    end do
    do a = 0, 2**ndim - 1
      c(:, a + 1) = i0
      wt(a + 1) = 1.0_wp
      do d = 1, ndim
        b = ibits(a, d - 1, 1)
        c(d, a + 1) = i0(d) + b
        wt(a + 1) = wt(a + 1) * merge(f(d), 1.0_wp - f(d), b == 1)
      end do
    end do
  end subroutine corners

  subroutine probe_least_squares(ndim, lo, hi, w, isreal, s, val, npts, bounded_from)
    integer, intent(in) :: ndim, lo(3), hi(3)
    real(wp), intent(in) :: w(lo(1):, lo(2):, lo(3):, :)
    logical, intent(in) :: isreal(lo(1):, lo(2):, lo(3):)
    real(wp), intent(in) :: s(3)
    real(wp), intent(out) :: val(:)
    integer, intent(out) :: npts
    integer, intent(in), optional :: bounded_from
    ! fixed sizes (a phase has at most max_var variables): automatic arrays would be taken
    ! from the heap on every call, and this runs once per ghost cell and stage
    real(wp) :: a(4, 4), rhs(4, max_var), row(4), wt, wsum(max_var)
    real(wp) :: wmin(max_var), wmax(max_var)
    integer :: ic(3), c(3), m, i, j, k, reach(3), r, nb, nv, p, q
    logical :: ok
    nv = size(val)
    if (nv > max_var) error stop 'probe_least_squares: more variables than max_var'
    nb = nv + 1
    if (present(bounded_from)) nb = bounded_from
    m = ndim + 1
    ic = 1
    ic(1:ndim) = min(max(nint(s(1:ndim)), lo(1:ndim)), hi(1:ndim))
    ! the 3^ndim nearest cells first; where their real ones do not span a linear fit (all on
    ! one line: a surface along a grid line) the 5^ndim nearest, weighted to the nearest
    do r = 1, 2
      reach = 0
      reach(1:ndim) = r
      a = 0.0_wp
      rhs = 0.0_wp
      wsum = 0.0_wp
      wmin = huge(1.0_wp)
      wmax = -huge(1.0_wp)
      npts = 0
      do k = ic(3) - reach(3), ic(3) + reach(3)
        do j = ic(2) - reach(2), ic(2) + reach(2)
          do i = ic(1) - reach(1), ic(1) + reach(1)
            c = [i, j, k]
            if (any(c < lo) .or. any(c > hi)) cycle
            if (.not. isreal(i, j, k)) cycle
            npts = npts + 1
            row(1) = 1.0_wp
            row(2:m) = real(c(1:ndim), wp) - s(1:ndim)
            wt = 1.0_wp / (1.0_wp + sum(row(2:m)**2))
            do q = 1, m
              do p = 1, m
                a(p, q) = a(p, q) + wt * row(p) * row(q)
              end do
            end do
            do q = 1, nv
              do p = 1, m
                rhs(p, q) = rhs(p, q) + wt * row(p) * w(i, j, k, q)
              end do
              wsum(q) = wsum(q) + w(i, j, k, q)
              wmin(q) = min(wmin(q), w(i, j, k, q))
              wmax(q) = max(wmax(q), w(i, j, k, q))
            end do
          end do
        end do
      end do
      if (npts >= m) then
        call solve_small(m, nv, a, rhs, ok)
        if (ok) then
          val = rhs(1, 1:nv)
          if (nb <= nv) val(nb:) = min(max(val(nb:), wmin(nb:nv)), wmax(nb:nv))
          return
        end if
      end if
    end do
    ! too few real neighbours (a thin sliver, a corner): the mean of those within two cells
    val = 0.0_wp
    if (npts > 0) val = wsum(1:nv) / real(npts, wp)
    npts = -npts
  end subroutine probe_least_squares

  !> Solve a(1:m, 1:m) x = b(1:m, 1:nv) in place (x in b) by Gaussian elimination with
  !> partial pivoting; ok is false when a pivot is below 1e-10 of the largest diagonal entry.
  pure subroutine solve_small(m, nv, a, b, ok)
    integer, intent(in) :: m, nv
    real(wp), intent(inout) :: a(:, :), b(:, :)
    logical, intent(out) :: ok
    integer :: c, r, p, v
    real(wp) :: scale, t, f, s
    scale = maxval([(abs(a(c, c)), c = 1, m)])
    ok = .false.
    do c = 1, m
      p = c - 1 + maxloc(abs(a(c:m, c)), 1)
      if (abs(a(p, c)) <= 1.0e-10_wp * scale) return
      if (p /= c) then
        do v = 1, size(a, 2)
          t = a(c, v)
          a(c, v) = a(p, v)
          a(p, v) = t
        end do
        do v = 1, nv
          t = b(c, v)
          b(c, v) = b(p, v)
          b(p, v) = t
        end do
      end if
      do r = c + 1, m
        f = a(r, c) / a(c, c)
        a(r, c:m) = a(r, c:m) - f * a(c, c:m)
        b(r, 1:nv) = b(r, 1:nv) - f * b(c, 1:nv)
      end do
    end do
    do c = m, 1, -1
      do v = 1, nv
        s = 0.0_wp
        do r = c + 1, m
          s = s + a(c, r) * b(r, v)
        end do
        b(c, v) = (b(c, v) - s) / a(c, c)
      end do
    end do
    ok = .true.
  end subroutine solve_small

  !> The field f of the padded block (bounds lo..hi) at the point sp (cell index
  !> coordinates): bilinear (trilinear in 3D) over the 2^ndim cells around it, the nearest
  !> inside the array.
  pure real(wp) function probe_scalar(ndim, lo, hi, f, sp) result(v)
    integer, intent(in) :: ndim, lo(3), hi(3)
    real(wp), intent(in) :: f(lo(1):, lo(2):, lo(3):), sp(3)
    integer :: c(3, 8), a, i0(3)
    real(wp) :: wt(8)
    call corners(ndim, lo, hi, sp, i0, c, wt)
    v = 0.0_wp
    do a = 1, 2**ndim
      v = v + wt(a) * f(c(1, a), c(2, a), c(3, a))
    end do
  end function probe_scalar

  !> The distance t in [t0, t1] along the ray from cell ijk in direction e (cell index units
  !> per unit length) at which f is least, of nine evenly spaced samples (the first least).
  pure real(wp) function deepest_on_ray(ndim, lo, hi, f, ijk, e, t0, t1) result(t)
    integer, intent(in) :: ndim, lo(3), hi(3), ijk(3)
    real(wp), intent(in) :: f(lo(1):, lo(2):, lo(3):), e(3), t0, t1
    integer :: m
    real(wp) :: tm, v, best, sp(3)
    best = huge(1.0_wp)
    t = t1
    do m = 0, 8
      tm = t0 + (t1 - t0) * real(m, wp) / 8.0_wp
      sp = real(ijk, wp)
      sp(1:ndim) = sp(1:ndim) + tm * e(1:ndim)
      v = probe_scalar(ndim, lo, hi, f, sp)
      if (v < best) then
        best = v
        t = tm
      end if
    end do
  end function deepest_on_ray

end module m_gfm_probe
