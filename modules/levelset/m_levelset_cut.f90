!> Cut-cell geometry of one phase on one block (manual/theory.md section 7, eqs. 7.1-7.6):
!> from a cell-centred level set phi (phi < 0 inside the phase, the convention of every
!> m_levelset_* and m_gfm) the face apertures A (the part of each face inside the phase),
!> the volume fraction alpha of each cell, and the interface of each cell as one vector
!> n S (unit normal n pointing out of the phase, along grad phi, times the area S; a length
!> in 2D). phi is first averaged to the cell corners (exact for a linear phi); along each
!> edge of a face phi is linear between its corners, so a face's wet part is the polygon that
!> the line phi = 0 clips from it (eq. 7.2). The interface vector is the imbalance of the
!> apertures, n S = sum_d (A_d(-) - A_d(+)) |face_d| e_d (eq. 7.3), so that the discrete
!> divergence identity sum_faces A |f| n_f + n S = 0 holds exactly in every cell: a constant
!> state feels no net force from the fluxes and the interface exchange together. alpha is
!> the clipped polygon's area in 2D; in 3D it comes from the divergence theorem in the cell's
!> unit coordinates with the mean of the edge crossings as the interface point (eq. 7.4).
!> Exact for a planar interface (linear phi) in 1D, 2D, 3D and axisymmetry; second order
!> for a curved one. In axisymmetry (x = r, y = z) volumes and faces carry 2 pi r: alpha is
!> the r-weighted fraction, the z-face apertures are r-weighted, and n S holds the planar
!> fraction's hoop term (eq. 7.5), which is also returned (alpha_plane) for the source
!> p / r. Kernels only: no MPI, no I/O, no state; not yet used by the time step (issue 15).
module m_levelset_cut
  use m_kinds, only: wp
  use m_levelset_geometry, only: unit_or_zero
  implicit none
  private
  public :: levelset_cut, levelset_cut_volume, cut_square_moments, cut_crossing

  real(wp), parameter :: two_pi = 6.28318530717958647692_wp

contains

  !> Cut-cell geometry of the n(1) x n(2) x n(3) interior cells of a block. phi has the halo
  !> g (at least 1 in every active direction, read, never written). r0 is the radius of the
  !> block's low x face (axisymmetric only). Outputs: ax(0:n1, n2, n3), ay(n1, 0:n2, n3),
  !> az(n1, n2, 0:n3) the apertures of the x, y, z faces (in an inactive direction the cell's
  !> planar fraction, the cross-section of the slab); alpha the volume fraction; area the
  !> interface area S (length in 2D, 1 or 0 in 1D, 2 pi r weighted in axisymmetry) and
  !> normal its unit normal, out of the phase (0 where a cell has no interface; both or
  !> neither: the cut-cell update, which needs only the apertures and fractions, leaves them
  !> out and saves their pass); alpha_plane the planar (un-weighted) fraction, which is alpha
  !> except in axisymmetry.
  subroutine levelset_cut(ndim, axisymmetric, n, g, dx, r0, phi, ax, ay, az, alpha, area, &
      normal, alpha_plane)
    integer, intent(in) :: ndim, n(3), g(3)
    logical, intent(in) :: axisymmetric
    real(wp), intent(in) :: dx(3), r0
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(out) :: ax(0:n(1), n(2), n(3)), ay(n(1), 0:n(2), n(3))
    real(wp), intent(out) :: az(n(1), n(2), 0:n(3))
    real(wp), intent(out) :: alpha(n(1), n(2), n(3))
    real(wp), intent(out), optional :: area(n(1), n(2), n(3)), normal(n(1), n(2), n(3), 3)
    real(wp), intent(out), optional :: alpha_plane(n(1), n(2), n(3))
    real(wp), allocatable :: c(:, :, :), plane(:, :, :)
    integer :: cl(3)
    logical :: axi
    ! corner (i, j, k) sits at (x_{i+1/2}, y_{j+1/2}, z_{k+1/2}); an inactive direction has
    ! the one index 1
    cl = merge(0, 1, [1, 2, 3] <= ndim)
    allocate(c(cl(1):n(1), cl(2):n(2), cl(3):n(3)), plane(n(1), n(2), n(3)))
    call corner_values(ndim, n, g, cl, phi, c)
    axi = axisymmetric .and. ndim == 2
    select case (ndim)
    case (1)
      call cut_1d(n, cl, c, ax, alpha)
      plane = alpha
    case (2)
      call cut_2d(axi, n, cl, dx, r0, c, ax, ay, alpha, plane)
    case default
      call cut_3d(n, c, ax, ay, az, alpha)
      plane = alpha
    end select
    if (ndim < 2) then
      ay(:, 0, :) = plane(:, 1, :)
      ay(:, 1, :) = plane(:, 1, :)
    end if
    if (ndim < 3) then
      az(:, :, 0) = plane(:, :, 1)
      az(:, :, 1) = plane(:, :, 1)
    end if
    if (present(area) .and. present(normal)) &
      call interface_vectors(ndim, axi, n, dx, r0, ax, ay, az, plane, area, normal)
    if (present(alpha_plane)) alpha_plane = plane
  end subroutine levelset_cut

  !> Volume of the phase over the interior cells of a block: sum alpha dV with the cell
  !> volumes of m_layout's cell_volume (2 pi r_c dr dz in axisymmetry).
  pure real(wp) function levelset_cut_volume(ndim, axisymmetric, n, dx, r0, alpha) result(vol)
    integer, intent(in) :: ndim, n(3)
    logical, intent(in) :: axisymmetric
    real(wp), intent(in) :: dx(3), r0
    real(wp), intent(in) :: alpha(n(1), n(2), n(3))
    integer :: i
    real(wp) :: w
    vol = 0.0_wp
    do i = 1, n(1)
      w = product(dx(1:ndim))
      if (axisymmetric .and. ndim == 2) w = w * two_pi * (r0 + (real(i, wp) - 0.5_wp) * dx(1))
      vol = vol + w * sum(alpha(i, :, :))
    end do
  end function levelset_cut_volume

  !> phi at the cell corners: the mean of the 2^ndim cells around each (exact for linear phi).
  !> Each term is scaled before the sum, so that the +-huge of a composite level set with no
  !> surface (m_levelset_bodies) cannot overflow.
  subroutine corner_values(ndim, n, g, cl, phi, c)
    integer, intent(in) :: ndim, n(3), g(3), cl(3)
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(out) :: c(cl(1):n(1), cl(2):n(2), cl(3):n(3))
    integer :: i, j, k, a, b, e, hi(3)
    real(wp) :: w, s
    hi = 1 - cl
    w = 1.0_wp / real(2**ndim, wp)
    if (ndim == 3) then
      ! (the same sum in the same order as below, written out so that it runs along i)
      do k = 0, n(3)
        do j = 0, n(2)
          do i = 0, n(1)
            s = 0.0_wp
            s = s + w * phi(i, j, k)
            s = s + w * phi(i+1, j, k)
            s = s + w * phi(i, j+1, k)
            s = s + w * phi(i+1, j+1, k)
            s = s + w * phi(i, j, k+1)
            s = s + w * phi(i+1, j, k+1)
            s = s + w * phi(i, j+1, k+1)
            s = s + w * phi(i+1, j+1, k+1)
            c(i, j, k) = s
          end do
        end do
      end do
      return
    end if
    do k = cl(3), n(3)
      do j = cl(2), n(2)
        do i = cl(1), n(1)
          s = 0.0_wp
          do e = 0, hi(3)
            do b = 0, hi(2)
              do a = 0, hi(1)
                s = s + w * phi(i+a, j+b, k+e)
              end do
            end do
          end do
          c(i, j, k) = s
        end do
      end do
    end do
  end subroutine corner_values

  !> 1D: a face is in the phase (A = 1) or not; the cell's fraction is the wet part of the
  !> segment between its two face values (eq. 7.1).
  subroutine cut_1d(n, cl, c, ax, alpha)
    integer, intent(in) :: n(3), cl(3)
    real(wp), intent(in) :: c(cl(1):n(1), cl(2):n(2), cl(3):n(3))
    real(wp), intent(out) :: ax(0:n(1), n(2), n(3)), alpha(n(1), n(2), n(3))
    integer :: i
    real(wp) :: s0, s1
    do i = 0, n(1)
      ax(i, 1, 1) = merge(1.0_wp, 0.0_wp, c(i, 1, 1) < 0.0_wp)
    end do
    do i = 1, n(1)
      call wet_interval(c(i-1, 1, 1), c(i, 1, 1), s0, s1)
      alpha(i, 1, 1) = s1 - s0
    end do
  end subroutine cut_1d

  !> 2D: edge apertures by linear interpolation along the edges (r-weighted on the z faces in
  !> axisymmetry), the cell's fraction from the clipped polygon's area and first moment in r.
  subroutine cut_2d(axi, n, cl, dx, r0, c, ax, ay, alpha, plane)
    logical, intent(in) :: axi
    integer, intent(in) :: n(3), cl(3)
    real(wp), intent(in) :: dx(3), r0
    real(wp), intent(in) :: c(cl(1):n(1), cl(2):n(2), cl(3):n(3))
    real(wp), intent(out) :: ax(0:n(1), n(2), n(3)), ay(n(1), 0:n(2), n(3))
    real(wp), intent(out) :: alpha(n(1), n(2), n(3)), plane(n(1), n(2), n(3))
    integer :: i, j
    real(wp) :: s0, s1, rl, rc, a, ms
    do j = 1, n(2)
      do i = 0, n(1)
        call wet_interval(c(i, j-1, 1), c(i, j, 1), s0, s1)
        ax(i, j, 1) = s1 - s0
      end do
    end do
    do j = 0, n(2)
      do i = 1, n(1)
        call wet_interval(c(i-1, j, 1), c(i, j, 1), s0, s1)
        ay(i, j, 1) = s1 - s0
        if (axi) then
          ! int r dr over the wet part / (r_c dr), r = r_l + s dr
          rl = r0 + real(i - 1, wp) * dx(1)
          rc = rl + 0.5_wp * dx(1)
          ay(i, j, 1) = min(1.0_wp, (s1 - s0) * (rl + 0.5_wp * (s0 + s1) * dx(1)) / rc)
        end if
      end do
    end do
    do j = 1, n(2)
      do i = 1, n(1)
        call cut_square_moments([c(i-1, j-1, 1), c(i, j-1, 1), c(i, j, 1), c(i-1, j, 1)], a, ms)
        plane(i, j, 1) = a
        alpha(i, j, 1) = a
        if (axi .and. a > 0.0_wp .and. a < 1.0_wp) then
          rl = r0 + real(i - 1, wp) * dx(1)
          rc = rl + 0.5_wp * dx(1)
          alpha(i, j, 1) = min(1.0_wp, max(0.0_wp, (rl * a + dx(1) * ms) / rc))
        end if
      end do
    end do
  end subroutine cut_2d

  !> 3D: each face's aperture is the clipped polygon of its four corners; the fraction is the
  !> divergence theorem in the unit cube about its centre (eq. 7.4),
  !> 3 alpha = sum_d (A_d(-) + A_d(+)) / 2 + xi_I . m,  m_d = A_d(-) - A_d(+),
  !> with xi_I the mean of the crossings on the cell's 12 edges (on the plane for a planar cut).
  subroutine cut_3d(n, c, ax, ay, az, alpha)
    integer, intent(in) :: n(3)
    real(wp), intent(in) :: c(0:n(1), 0:n(2), 0:n(3))
    real(wp), intent(out) :: ax(0:n(1), n(2), n(3)), ay(n(1), 0:n(2), n(3))
    real(wp), intent(out) :: az(n(1), n(2), 0:n(3))
    real(wp), intent(out) :: alpha(n(1), n(2), n(3))
    integer :: i, j, k
    real(wp) :: p(0:1, 0:1, 0:1)
    call face_apertures(1, n, c, ax)
    call face_apertures(2, n, c, ay)
    call face_apertures(3, n, c, az)
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          p = c(i-1:i, j-1:j, k-1:k)
          alpha(i, j, k) = cube_fraction(p, &
            [ax(i-1, j, k), ax(i, j, k), ay(i, j-1, k), ay(i, j, k), az(i, j, k-1), az(i, j, k)])
        end do
      end do
    end do
  end subroutine cut_3d

  !> 3D: the apertures of the faces normal to direction d (0:n(d) along d): each face's
  !> clipped polygon of its four corners, taken round the face from its low corner.
  subroutine face_apertures(d, n, c, apt)
    integer, intent(in) :: d, n(3)
    real(wp), intent(in) :: c(0:n(1), 0:n(2), 0:n(3))
    real(wp), intent(out) :: apt(merge(0, 1, d == 1):n(1), merge(0, 1, d == 2):n(2), &
      merge(0, 1, d == 3):n(3))
    integer :: i, j, k, lo(3), u(3), w(3), b(3)
    real(wp) :: a, ms, p(4)
    lo = merge(0, 1, [1, 2, 3] == d)
    ! u, w: the unit steps along the face's two tangent directions
    u = 0
    w = 0
    u(mod(d, 3) + 1) = 1
    w(mod(d + 1, 3) + 1) = 1
    do k = lo(3), n(3)
      do j = lo(2), n(2)
        do i = lo(1), n(1)
          b = [i, j, k] - u - w
          p = [c(b(1), b(2), b(3)), c(b(1)+u(1), b(2)+u(2), b(3)+u(3)), c(i, j, k), &
            c(b(1)+w(1), b(2)+w(2), b(3)+w(3))]
          ! (a face wholly in or out, most of them, as cut_square_moments has it, without
          ! the call)
          if (all(p < 0.0_wp)) then
            apt(i, j, k) = 1.0_wp
          else if (all(.not. p < 0.0_wp)) then
            apt(i, j, k) = 0.0_wp
          else
            call cut_square_moments(p, a, ms)
            apt(i, j, k) = a
          end if
        end do
      end do
    end do
  end subroutine face_apertures

  !> Volume fraction of a cube from its 8 corner values p(0:1, 0:1, 0:1) and its 6 face
  !> apertures (x-, x+, y-, y+, z-, z+).
  pure real(wp) function cube_fraction(p, apt) result(alpha)
    real(wp), intent(in) :: p(0:1, 0:1, 0:1), apt(6)
    real(wp) :: xi(3), t, m(3)
    integer :: a, b, d, ncross, v(3), w(3)
    if (all(p < 0.0_wp)) then
      alpha = 1.0_wp
      return
    end if
    if (all(.not. p < 0.0_wp)) then
      alpha = 0.0_wp
      return
    end if
    xi = 0.0_wp
    ncross = 0
    ! the 12 edges: along direction d from corner v (v_d = 0) to w
    do d = 1, 3
      do b = 0, 1
        do a = 0, 1
          v = 0
          select case (d)
          case (1)
            v(2:3) = [a, b]
          case (2)
            v(1) = a
            v(3) = b
          case default
            v(1:2) = [a, b]
          end select
          w = v
          w(d) = 1
          if ((p(v(1), v(2), v(3)) < 0.0_wp) .eqv. (p(w(1), w(2), w(3)) < 0.0_wp)) cycle
          t = cut_crossing(p(v(1), v(2), v(3)), p(w(1), w(2), w(3)))
          xi = xi + real(v, wp) - 0.5_wp
          xi(d) = xi(d) + t
          ncross = ncross + 1
        end do
      end do
    end do
    xi = xi / real(ncross, wp)
    m = [apt(1) - apt(2), apt(3) - apt(4), apt(5) - apt(6)]
    alpha = (0.5_wp * sum(apt) + dot_product(xi, m)) / 3.0_wp
    alpha = min(1.0_wp, max(0.0_wp, alpha))
  end function cube_fraction

  !> n S of every cell from the apertures (eq. 7.3; eq. 7.5 in axisymmetry, where the r
  !> faces' imbalance is closed by the planar fraction), its length S and direction n.
  subroutine interface_vectors(ndim, axi, n, dx, r0, ax, ay, az, plane, area, normal)
    integer, intent(in) :: ndim, n(3)
    logical, intent(in) :: axi
    real(wp), intent(in) :: dx(3), r0
    real(wp), intent(in) :: ax(0:n(1), n(2), n(3)), ay(n(1), 0:n(2), n(3))
    real(wp), intent(in) :: az(n(1), n(2), 0:n(3)), plane(n(1), n(2), n(3))
    real(wp), intent(out) :: area(n(1), n(2), n(3)), normal(n(1), n(2), n(3), 3)
    real(wp) :: f(3), v(3), rm, rc
    integer :: i, j, k
    f = 1.0_wp
    if (ndim >= 2) f(1:2) = [dx(2), dx(1)]
    if (ndim == 3) f = [dx(2) * dx(3), dx(1) * dx(3), dx(1) * dx(2)]
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          v = [(ax(i-1, j, k) - ax(i, j, k)) * f(1), (ay(i, j-1, k) - ay(i, j, k)) * f(2), &
            (az(i, j, k-1) - az(i, j, k)) * f(3)]
          if (ndim < 3) v(3) = 0.0_wp
          if (ndim < 2) v(2) = 0.0_wp
          if (axi) then
            ! 2 pi [r_- A_- dz - r_+ A_+ dz + alpha_plane dr dz, r_c dr (A_- - A_+)], with
            ! r_+ = r_- + dr written out so that a full cell gives exactly zero
            rm = r0 + real(i - 1, wp) * dx(1)
            rc = rm + 0.5_wp * dx(1)
            v(1) = two_pi * dx(2) * ((ax(i-1, j, k) - ax(i, j, k)) * rm &
              + (plane(i, j, k) - ax(i, j, k)) * dx(1))
            v(2) = two_pi * rc * v(2)
          end if
          area(i, j, k) = norm2(v)
          normal(i, j, k, :) = unit_or_zero(v)
        end do
      end do
    end do
  end subroutine interface_vectors

  !> The wet part [s0, s1] of an edge from value pa (s = 0) to pb (s = 1), phi linear along
  !> it; s0 = s1 = 0 when dry.
  pure subroutine wet_interval(pa, pb, s0, s1)
    real(wp), intent(in) :: pa, pb
    real(wp), intent(out) :: s0, s1
    logical :: ia, ib
    ia = pa < 0.0_wp
    ib = pb < 0.0_wp
    s0 = 0.0_wp
    s1 = 0.0_wp
    if (ia .and. ib) then
      s1 = 1.0_wp
    else if (ia) then
      s1 = cut_crossing(pa, pb)
    else if (ib) then
      s0 = cut_crossing(pa, pb)
      s1 = 1.0_wp
    end if
  end subroutine wet_interval

  !> Where phi = 0 on an edge from pa (s = 0) to pb (s = 1), for pa, pb on either side of
  !> zero (one < 0, the other >= 0): s = |pa| / (|pa| + |pb|), written to overflow for
  !> no values.
  elemental real(wp) function cut_crossing(pa, pb) result(s)
    real(wp), intent(in) :: pa, pb
    real(wp) :: a, b
    a = abs(pa)
    b = abs(pb)
    if (a >= b) then
      s = 1.0_wp / (1.0_wp + b / a)
    else
      s = (a / b) / (1.0_wp + a / b)
    end if
  end function cut_crossing

  !> Area a and first moment ms = int s dA of the part phi < 0 of the unit square, phi linear
  !> along its edges with corner values p = (p(0,0), p(1,0), p(1,1), p(0,1)) at (s, t):
  !> the square clipped at the edges' crossings (Sutherland-Hodgman) and the polygon's area
  !> and moment by the shoelace sums (eq. 7.2). Two opposite wet corners (a saddle) are
  !> joined through the centre.
  pure subroutine cut_square_moments(p, a, ms)
    real(wp), intent(in) :: p(4)
    real(wp), intent(out) :: a, ms
    real(wp), parameter :: xs(4) = [0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp]
    real(wp), parameter :: ys(4) = [0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp]
    real(wp) :: px(8), py(8), t, cr
    integer :: m, q, nv, nxt
    if (all(p < 0.0_wp)) then
      a = 1.0_wp
      ms = 0.5_wp
      return
    end if
    if (all(.not. p < 0.0_wp)) then
      a = 0.0_wp
      ms = 0.0_wp
      return
    end if
    nv = 0
    do m = 1, 4
      nxt = mod(m, 4) + 1
      if (p(m) < 0.0_wp) then
        nv = nv + 1
        px(nv) = xs(m)
        py(nv) = ys(m)
      end if
      if ((p(m) < 0.0_wp) .neqv. (p(nxt) < 0.0_wp)) then
        t = cut_crossing(p(m), p(nxt))
        nv = nv + 1
        px(nv) = xs(m) + t * (xs(nxt) - xs(m))
        py(nv) = ys(m) + t * (ys(nxt) - ys(m))
      end if
    end do
    a = 0.0_wp
    ms = 0.0_wp
    do m = 1, nv
      q = mod(m, nv) + 1
      cr = px(m) * py(q) - px(q) * py(m)
      a = a + cr
      ms = ms + (px(m) + px(q)) * cr
    end do
    a = min(1.0_wp, max(0.0_wp, 0.5_wp * a))
    ms = ms / 6.0_wp
  end subroutine cut_square_moments

end module m_levelset_cut
