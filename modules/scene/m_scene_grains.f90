!> Voronoi grains with binder layers (issue 16 points 2 and 3; manual/scenes.md): grain i is
!> its Voronoi cell among random seeds (m_scene_generate's random_points) shrunk by half the
!> binder thickness, the thickness from a binder volume fraction; grains that come within a
!> ghost band of each other get different colours, and each colour is one level set (so one
!> phase) of the grains' material: 1024 grains cost a handful of level sets. make_grains builds
!> a body's grains once at set-up (every rank alike, plain arithmetic on the seed) and
!> grains_distance is the level set of one colour at a point: each seed carries the list of
!> seeds within reach of it and the seeds sit in bins, so a point costs a few dozen planes,
!> not a pass over every grain.
module m_scene_grains
  use m_kinds, only: wp
  use m_scene_generate, only: random_points
  implicit none
  private
  public :: grains_t, grain_distance, binder_thickness, grain_conflicts, colour_graph
  public :: make_grains, grains_distance

  !> Voronoi grains as make_grains makes them: the seeds, each grain's colour (its level
  !> set), the seeds within reach of each seed (grain k's are near(first(k):first(k + 1) - 1))
  !> and the seeds in bins (head, next), the binder thickness, and the distance beyond which
  !> a grain's level set is held at that value.
  type :: grains_t
    real(wp), allocatable :: seed(:, :)                     !< (3, n)
    integer, allocatable :: colour(:), first(:), near(:), head(:), next(:)
    integer :: ncolour = 0, nbin(3) = 1
    integer :: needed = 0     !< colours the ghost band needs (ncolour unless &body colours cut it)
    real(wp) :: thickness = 0.0_wp, cap = 0.0_wp, bin = 1.0_wp
  end type grains_t

contains

  !> The grains of a body: count seeds in the box lo..hi at least 0.6 of their mean spacing
  !> apart, the binder thickness that leaves the grains volume_fraction of the box (measured
  !> on a raster of a tenth of the spacing), colours such that no two grains of one colour
  !> come within g (the ghost band, a length) of each other, each seed's near seeds and the
  !> bins. achieved is the grains' volume fraction on that raster; why is '' or why the
  !> grains could not be made.
  !> max_colours > 0 (&body colours) deals the colours into at most that many level sets:
  !> grains nearer than g may then share one, and the binder layer between them is seen by
  !> one level set only (its ghost bands overlap). It is there to measure what the colours
  !> cost (manual/hotspots.md section 5), not for results.
  subroutine make_grains(ndim, lo, hi, seed, count, volume_fraction, g, gr, achieved, why, &
      max_colours)
    integer, intent(in) :: ndim, seed, count
    integer, intent(in), optional :: max_colours
    real(wp), intent(in) :: lo(3), hi(3), volume_fraction, g
    type(grains_t), intent(out) :: gr
    real(wp), intent(out) :: achieved
    character(len=:), allocatable, intent(out) :: why
    real(wp), allocatable :: c(:, :)
    logical, allocatable :: conflict(:, :)
    real(wp) :: s0, rmax, reach, x(3)
    integer :: n(3), i, j, k, a, nin
    logical :: ok
    why = ''
    achieved = 0.0_wp
    s0 = (product(hi(1:ndim) - lo(1:ndim)) / count)**(1.0_wp / ndim)
    ! a grain's level set is held at cap = s0 beyond it: the ghost band must fit inside
    if (s0 < g) then
      why = 'the grains are too small for the mesh: their spacing must exceed the ghost ' &
        // 'band (band cells); refine the mesh or give fewer grains'
      return
    end if
    call random_points(ndim, lo, hi, seed, count, 0.6_wp * s0, c, ok)
    if (.not. ok) then
      why = 'the seeds of the grains found no place (lower count)'
      return
    end if
    call binder_thickness(c, ndim, lo, hi, 1.0_wp - volume_fraction, 0.1_wp * s0, &
      gr%thickness)
    call grain_conflicts(c, ndim, lo, hi, gr%thickness, g, conflict)
    allocate(gr%colour(count))
    call colour_graph(conflict, gr%colour, gr%ncolour)
    gr%needed = gr%ncolour
    if (present(max_colours)) then
      if (max_colours > 0 .and. gr%ncolour > max_colours) then
        gr%colour = modulo(gr%colour - 1, max_colours) + 1
        gr%ncolour = max_colours
      end if
    end if
    gr%seed = c
    gr%cap = s0
    ! bins of side s0 over the box, each seed in the bin of its position
    gr%bin = s0
    gr%nbin = 1
    gr%nbin(1:ndim) = max(1, ceiling((hi(1:ndim) - lo(1:ndim)) / s0))
    allocate(gr%head(product(gr%nbin)), gr%next(count))
    gr%head = 0
    do a = count, 1, -1
      k = bin_number(gr, bin_of(gr, ndim, lo, c(:, a)))
      gr%next(a) = gr%head(k)
      gr%head(k) = a
    end do
    ! the farthest a point of the box lies from its nearest seed (on the raster, plus its
    ! half diagonal): seeds farther than reach from a point's nearest seed hold their
    ! grains at least s0 from the point, so they need not be looked at
    n = 1
    n(1:ndim) = max(1, nint((hi(1:ndim) - lo(1:ndim)) / (0.1_wp * s0)))
    rmax = 0.0_wp
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          x = raster_point(lo, hi, n, i, j, k)
          rmax = max(rmax, norm2(x(1:ndim) - c(1:ndim, nearest_seed(gr, ndim, lo, x))))
        end do
      end do
    end do
    rmax = rmax + 0.5_wp * norm2((hi(1:ndim) - lo(1:ndim)) / n(1:ndim))
    reach = 2.0_wp * rmax + 2.0_wp * s0
    allocate(gr%first(count + 1))
    gr%first(1) = 1
    allocate(gr%near(0))
    do a = 1, count
      gr%near = [gr%near, pack([(j, j = 1, count)], [(j /= a .and. &
        norm2(c(1:ndim, j) - c(1:ndim, a)) < reach, j = 1, count)])]
      gr%first(a + 1) = size(gr%near) + 1
    end do
    nin = 0
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          if (grains_distance(gr, ndim, lo, hi, 0, raster_point(lo, hi, n, i, j, k)) < 0.0_wp) &
            nin = nin + 1
        end do
      end do
    end do
    achieved = real(nin, wp) / product(n)
  end subroutine make_grains

  !> The bin (i, j, k) of the point x in the grains' bins over the box from lo (a point
  !> outside the box: the nearest bin).
  pure function bin_of(gr, ndim, lo, x) result(ib)
    type(grains_t), intent(in) :: gr
    integer, intent(in) :: ndim
    real(wp), intent(in) :: lo(3), x(3)
    integer :: ib(3)
    ib = 1
    ib(1:ndim) = min(gr%nbin(1:ndim), max(1, 1 + int((x(1:ndim) - lo(1:ndim)) / gr%bin)))
  end function bin_of

  !> The number (1-based, x fastest) of bin ib.
  pure integer function bin_number(gr, ib) result(k)
    type(grains_t), intent(in) :: gr
    integer, intent(in) :: ib(3)
    k = ib(1) + gr%nbin(1) * (ib(2) - 1 + gr%nbin(2) * (ib(3) - 1))
  end function bin_number

  !> The level set of the grains of colour `colour` (0: of every grain) at x: the signed
  !> distance of grain_distance to the nearest of them, exact inside a grain and near it,
  !> held at gr%cap (the mean spacing of the seeds) farther out. Only the seed nearest to x
  !> and its near seeds can hold a grain within cap of x, and only a seed's near seeds can
  !> bound its grain where that is so (every Voronoi neighbour is near).
  pure real(wp) function grains_distance(gr, ndim, lo, hi, colour, x) result(d)
    type(grains_t), intent(in) :: gr
    integer, intent(in) :: ndim, colour
    real(wp), intent(in) :: lo(3), hi(3), x(3)
    integer :: n0, m, a
    real(wp) :: box
    n0 = nearest_seed(gr, ndim, lo, x)
    box = maxval(max(lo(1:ndim) - x(1:ndim), x(1:ndim) - hi(1:ndim)))
    d = gr%cap
    do m = gr%first(n0) - 1, gr%first(n0 + 1) - 1
      a = n0
      if (m >= gr%first(n0)) a = gr%near(m)
      if (colour > 0 .and. gr%colour(a) /= colour) cycle
      d = min(d, own(a))
    end do

  contains

    !> grain a's distance by the bisector planes with its near seeds, clipped by the box;
    !> left as soon as it reaches d (it cannot lower d then), the plane with the nearest
    !> seed first (for a grain other than the nearest seed's it mostly ends there)
    pure real(wp) function own(ia)
      integer, intent(in) :: ia
      integer :: mm
      own = box
      if (ia /= n0) own = max(own, plane(ia, n0))
      do mm = gr%first(ia), gr%first(ia + 1) - 1
        if (own >= d) return
        own = max(own, plane(ia, gr%near(mm)))
      end do
    end function own

    !> the signed distance from x to the bisector of seeds i and j, moved by half the binder
    pure real(wp) function plane(i, j)
      integer, intent(in) :: i, j
      plane = (sum((x(1:ndim) - gr%seed(1:ndim, i))**2) - sum((x(1:ndim) &
        - gr%seed(1:ndim, j))**2)) / (2.0_wp * norm2(gr%seed(1:ndim, i) - gr%seed(1:ndim, j))) &
        + 0.5_wp * gr%thickness
    end function plane

  end function grains_distance

  !> The seed nearest to x: the bins in rings around x's bin until no unvisited bin can
  !> hold a nearer seed.
  pure integer function nearest_seed(gr, ndim, lo, x) result(best)
    type(grains_t), intent(in) :: gr
    integer, intent(in) :: ndim
    real(wp), intent(in) :: lo(3), x(3)
    integer :: ib(3), r, i, j, k, s, lim(3)
    real(wp) :: dbest, dd
    ib = bin_of(gr, ndim, lo, x)
    best = 1
    dbest = huge(1.0_wp)
    lim = 0
    do r = 0, maxval(gr%nbin)
      lim(1:ndim) = r
      do k = ib(3) - lim(3), ib(3) + lim(3)
        do j = ib(2) - lim(2), ib(2) + lim(2)
          do i = ib(1) - lim(1), ib(1) + lim(1)
            ! the ring only: a bin of the inner rings was visited before
            if (maxval(abs([i, j, k] - ib)) /= r) cycle
            if (any([i, j, k] < 1) .or. any([i, j, k] > gr%nbin)) cycle
            s = gr%head(bin_number(gr, [i, j, k]))
            do while (s > 0)
              dd = norm2(x(1:ndim) - gr%seed(1:ndim, s))
              if (dd < dbest) then
                dbest = dd
                best = s
              end if
              s = gr%next(s)
            end do
          end do
        end do
      end do
      ! a bin of ring r + 1 lies at least r bins from x
      if (dbest <= real(r, wp) * gr%bin) exit
    end do
  end function nearest_seed

  !> Level set of grain i (negative inside) among the Voronoi seeds c(3, n): its cell shrunk
  !> by half the binder thickness t, as the largest signed distance to the bisector planes,
  !> clipped by the box lo..hi. Exact inside a grain; outside, never more than the distance
  !> (each plane's distance is a lower bound), so a test "within g" by it is conservative.
  pure real(wp) function grain_distance(c, i, ndim, lo, hi, t, x) result(d)
    real(wp), intent(in) :: c(:, :), lo(3), hi(3), t, x(3)
    integer, intent(in) :: i, ndim
    integer :: j
    real(wp) :: e
    d = maxval(max(lo(1:ndim) - x(1:ndim), x(1:ndim) - hi(1:ndim)))
    do j = 1, size(c, 2)
      if (j == i) cycle
      e = norm2(c(1:ndim, i) - c(1:ndim, j))
      d = max(d, (sum((x(1:ndim) - c(1:ndim, i))**2) - sum((x(1:ndim) - c(1:ndim, j))**2)) &
        / (2.0_wp * e) + 0.5_wp * t)
    end do
  end function grain_distance

  !> The binder thickness t such that the binder (the layers of thickness t centred on the
  !> Voronoi faces between the seeds c) fills volume_fraction of the box lo..hi, measured on
  !> a raster of spacing h: t / 2 is that quantile of the distance of the raster points to
  !> the face of their own cell. A binder mass fraction w of density rho_b among grains of
  !> rho_g is the volume fraction (w / rho_b) / (w / rho_b + (1 - w) / rho_g).
  subroutine binder_thickness(c, ndim, lo, hi, volume_fraction, h, t)
    real(wp), intent(in) :: c(:, :), lo(3), hi(3), volume_fraction, h
    integer, intent(in) :: ndim
    real(wp), intent(out) :: t
    real(wp), allocatable :: w(:)
    real(wp) :: x(3), b(size(c, 2)), tlo, thi, tm
    integer :: n(3), i, j, k, m, near, it
    n = 1
    n(1:ndim) = max(1, nint((hi(1:ndim) - lo(1:ndim)) / h))
    allocate(w(product(n)))
    m = 0
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          x = raster_point(lo, hi, n, i, j, k)
          b = [(norm2(x(1:ndim) - c(1:ndim, near)), near = 1, size(c, 2))]
          near = minloc(b, 1)
          m = m + 1
          w(m) = huge(1.0_wp)
          do it = 1, size(c, 2)
            if (it /= near) w(m) = min(w(m), (b(it)**2 - b(near)**2) &
              / (2.0_wp * norm2(c(1:ndim, it) - c(1:ndim, near))))
          end do
        end do
      end do
    end do
    ! the quantile by bisection on the value (no sort of a large raster)
    tlo = 0.0_wp
    thi = maxval(w)
    do it = 1, 200
      tm = 0.5_wp * (tlo + thi)
      if (count(w < tm) >= volume_fraction * size(w)) then
        thi = tm
      else
        tlo = tm
      end if
      if (thi - tlo <= 1.0e-12_wp * thi) exit
    end do
    t = 2.0_wp * thi
  end subroutine binder_thickness

  !> The centre of raster cell (i, j, k) of n cells over lo..hi.
  pure function raster_point(lo, hi, n, i, j, k) result(x)
    real(wp), intent(in) :: lo(3), hi(3)
    integer, intent(in) :: n(3), i, j, k
    real(wp) :: x(3)
    x = lo + (real([i, j, k], wp) - 0.5_wp) * (hi - lo) / real(n, wp)
  end function raster_point

  !> Which grains (seeds c, binder thickness t, box lo..hi) come within g of each other:
  !> conflict(i, j) when some point of the box lies within g / 2 of both, found on a raster
  !> of spacing about g / 3 with the raster's half diagonal added to g / 2 (grain_distance
  !> is 1-Lipschitz and never above the distance), so no pair closer than g is missed; a
  !> pair a little farther may be taken as conflicting too.
  subroutine grain_conflicts(c, ndim, lo, hi, t, g, conflict)
    real(wp), intent(in) :: c(:, :), lo(3), hi(3), t, g
    integer, intent(in) :: ndim
    logical, allocatable, intent(out) :: conflict(:, :)
    real(wp) :: x(3), b(size(c, 2)), reach, hx(3), bmin
    integer :: n(3), i, j, k, a, e, ncand, cand(size(c, 2))
    integer :: ng
    ng = size(c, 2)
    allocate(conflict(ng, ng))
    conflict = .false.
    n = 1
    n(1:ndim) = max(1, ceiling((hi(1:ndim) - lo(1:ndim)) / (g / 3.0_wp)))
    hx = (hi - lo) / real(n, wp)
    reach = 0.5_wp * g + 0.5_wp * norm2(hx(1:ndim))
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          x = raster_point(lo, hi, n, i, j, k)
          b = [(norm2(x(1:ndim) - c(1:ndim, a)), a = 1, ng)]
          bmin = minval(b)
          ! grain a is within reach of x only if b(a) < bmin + 2 reach - t (its bisector
          ! with the nearest seed is farther otherwise)
          ncand = 0
          do a = 1, ng
            if (b(a) > bmin .and. b(a) >= bmin + 2.0_wp * reach - t) cycle
            if (.not. within(a)) cycle
            ncand = ncand + 1
            cand(ncand) = a
          end do
          do a = 1, ncand
            do e = a + 1, ncand
              conflict(cand(a), cand(e)) = .true.
              conflict(cand(e), cand(a)) = .true.
            end do
          end do
        end do
      end do
    end do

  contains

    !> grain_distance(a) at x < reach; a seed j farther from x than seed a has a bisector
    !> distance <= (b(a) - b(j)) / 2, so only those with b(j) <= b(a) + t - 2 reach or
    !> nearer than seed a can push it up to reach
    logical function within(ia)
      integer, intent(in) :: ia
      integer :: jb
      real(wp) :: d
      within = .false.
      if (maxval(max(lo(1:ndim) - x(1:ndim), x(1:ndim) - hi(1:ndim))) >= reach) return
      do jb = 1, ng
        if (jb == ia .or. b(jb) > max(b(ia), b(ia) + t - 2.0_wp * reach)) cycle
        d = (b(ia)**2 - b(jb)**2) / (2.0_wp * norm2(c(1:ndim, ia) - c(1:ndim, jb))) + 0.5_wp * t
        if (d >= reach) return
      end do
      within = .true.
    end function within

  end subroutine grain_conflicts

  !> Greedy colouring of the graph adj (symmetric, no self loops) by DSATUR (Brelaz 1979):
  !> repeatedly colour the vertex whose neighbours already use the most colours (ties: the
  !> most neighbours, then the lowest index) with the lowest colour none of them uses.
  !> colour(k) in 1..ncolours; O(n^2).
  subroutine colour_graph(adj, colour, ncolours)
    logical, intent(in) :: adj(:, :)
    integer, intent(out) :: colour(size(adj, 1)), ncolours
    logical, allocatable :: seen(:, :)   ! seen(c, v): a neighbour of v has colour c
    integer :: n, step, v, k, c, sat(size(adj, 1)), deg(size(adj, 1))
    n = size(adj, 1)
    deg = count(adj, 2)
    ! no vertex needs a colour above its degree + 1
    allocate(seen(maxval([0, deg]) + 2, n))
    seen = .false.
    sat = 0
    colour = 0
    ncolours = 0
    do step = 1, n
      v = 0
      do k = 1, n
        if (colour(k) > 0) cycle
        if (v == 0) then
          v = k
        else if (sat(k) > sat(v) .or. (sat(k) == sat(v) .and. deg(k) > deg(v))) then
          v = k
        end if
      end do
      c = findloc(seen(:, v), .false., 1)
      colour(v) = c
      ncolours = max(ncolours, c)
      do k = 1, n
        if (.not. adj(k, v) .or. seen(c, k)) cycle
        seen(c, k) = .true.
        sat(k) = sat(k) + 1
      end do
    end do
  end subroutine colour_graph

end module m_scene_grains
