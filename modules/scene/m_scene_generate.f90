!> Scene generators of random microstructures (issue 16 point 3; manual/scenes.md): the
!> portable random numbers they draw (xoshiro256**, seeded from the deck's integer seed),
!> random non-overlapping spheres (circles in 2D) at a volume fraction or count with a size
!> distribution and a minimum gap, inside a box (random sequential addition, largest first);
!> the seeds of Voronoi grains (the grains themselves are m_scene_grains). The Gaussian
!> random field is m_scene_field. Everything here is plain arithmetic on the seed: every rank
!> draws the same numbers and builds the same scene, so no rank talks to another. It does not
!> paint the scene onto blocks (m_scene) or read the deck (m_deck).
module m_scene_generate
  use m_kinds, only: wp, i8
  use m_text, only: int_text
  implicit none
  private
  public :: rng_t, rng_seed, rng_next, rng_uniform, rng_normal
  public :: random_spheres, sphere_volume, spheres_distance
  public :: random_points

  real(wp), parameter :: pi = 4.0_wp * atan(1.0_wp)
  !> placements tried for one sphere before the generator gives up
  integer, parameter :: max_tries = 200000

  !> xoshiro256** (Blackman and Vigna 2018): 256 bits of state, shifts, rotations, xors and
  !> additions modulo 2^64 done on 32-bit halves, so that no signed integer overflows and
  !> the stream is the same with any compiler on any machine.
  type :: rng_t
    integer(i8) :: s(4) = 0_i8
  end type rng_t

contains

  !> The generator started from seed: its four words are successive values of Marsaglia's
  !> xorshift64 from the seed (never all zero), and the first 16 outputs are dropped.
  pure subroutine rng_seed(rng, seed)
    type(rng_t), intent(out) :: rng
    integer, intent(in) :: seed
    integer(i8) :: x, discard
    integer :: k
    x = ieor(int(seed, i8), int(z'1E3779B97F4A7C15', i8))
    if (x == 0_i8) x = 1_i8
    do k = 1, 4
      x = ieor(x, ishft(x, 13))
      x = ieor(x, ishft(x, -7))
      x = ieor(x, ishft(x, 17))
      rng%s(k) = x
    end do
    do k = 1, 16
      call rng_next(rng, discard)
    end do
  end subroutine rng_seed

  !> The next 64 bits of xoshiro256**.
  pure subroutine rng_next(rng, r)
    type(rng_t), intent(inout) :: rng
    integer(i8), intent(out) :: r
    integer(i8) :: t
    r = times9(ishftc(times5(rng%s(2)), 7))
    t = ishft(rng%s(2), 17)
    rng%s(3) = ieor(rng%s(3), rng%s(1))
    rng%s(4) = ieor(rng%s(4), rng%s(2))
    rng%s(2) = ieor(rng%s(2), rng%s(3))
    rng%s(1) = ieor(rng%s(1), rng%s(4))
    rng%s(3) = ieor(rng%s(3), t)
    rng%s(4) = ishftc(rng%s(4), 45)
  end subroutine rng_next

  !> a + b modulo 2^64 on the bit patterns, in 32-bit halves (no overflow)
  elemental integer(i8) function add64(a, b) result(c)
    integer(i8), intent(in) :: a, b
    integer(i8), parameter :: low32 = int(z'FFFFFFFF', i8)
    integer(i8) :: lo, hi
    lo = iand(a, low32) + iand(b, low32)
    hi = ishft(a, -32) + ishft(b, -32) + ishft(lo, -32)
    c = ior(ishft(hi, 32), iand(lo, low32))
  end function add64

  elemental integer(i8) function times5(a)
    integer(i8), intent(in) :: a
    times5 = add64(ishft(a, 2), a)
  end function times5

  elemental integer(i8) function times9(a)
    integer(i8), intent(in) :: a
    times9 = add64(ishft(a, 3), a)
  end function times9

  !> Uniform in [0, 1): the top 53 bits of the next output.
  real(wp) function rng_uniform(rng) result(u)
    type(rng_t), intent(inout) :: rng
    integer(i8) :: r
    call rng_next(rng, r)
    u = real(ishft(r, -11), wp) * 2.0_wp**(-53)
  end function rng_uniform

  !> Standard normal (Box-Muller, the cosine branch only: one normal per two uniforms).
  real(wp) function rng_normal(rng) result(z)
    type(rng_t), intent(inout) :: rng
    real(wp) :: u1, u2
    u1 = 1.0_wp - rng_uniform(rng)   ! in (0, 1]
    u2 = rng_uniform(rng)
    z = sqrt(-2.0_wp * log(u1)) * cos(2.0_wp * pi * u2)
  end function rng_normal

  !> Volume of a sphere of radius r in ndim dimensions (area of a circle in 2D, length of a
  !> segment in 1D).
  elemental real(wp) function sphere_volume(ndim, r) result(v)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: r
    select case (ndim)
    case (1)
      v = 2.0_wp * r
    case (2)
      v = pi * r**2
    case default
      v = 4.0_wp / 3.0_wp * pi * r**3
    end select
  end function sphere_volume

  !> Random non-overlapping spheres in the box lo..hi (its first ndim directions): count of
  !> them, or (count 0) as many as bring their volume closest to fraction of the box. Radii:
  !> 'fixed' radius; 'uniform' in [radius_min, radius_max]; 'lognormal' radius exp(sigma z),
  !> redrawn until in [radius_min, radius_max] where those are > 0. Placed largest first,
  !> each at uniform random centres until it keeps gap from every sphere placed and from the
  !> box faces. spheres(1:3, k) is the centre, spheres(4, k) the radius; achieved the volume
  !> fraction placed; why is '' or why it could not be done.
  subroutine random_spheres(ndim, lo, hi, seed, fraction, count, distribution, radius, &
      radius_min, radius_max, sigma, gap, spheres, achieved, why)
    integer, intent(in) :: ndim, seed, count
    real(wp), intent(in) :: lo(3), hi(3), fraction, radius, radius_min, radius_max, sigma, gap
    character(len=*), intent(in) :: distribution
    real(wp), allocatable, intent(out) :: spheres(:, :)
    real(wp), intent(out) :: achieved
    character(len=:), allocatable, intent(out) :: why
    type(rng_t) :: rng
    real(wp), allocatable :: r(:)
    real(wp) :: box, target, v, rk
    integer :: n
    logical :: ok
    why = ''
    call rng_seed(rng, seed)
    box = product(hi(1:ndim) - lo(1:ndim))
    target = fraction * box
    allocate(r(0))
    v = 0.0_wp
    do
      if (count > 0 .and. size(r) == count) exit
      if (size(r) > 10000000) then
        why = 'more than 10^7 spheres'
        return
      end if
      rk = draw_radius()
      if (.not. rk > 0.0_wp) then
        why = 'no radius drawn in [radius_min, radius_max] in 1000 tries'
        return
      end if
      if (count == 0) then   ! stop where the volume is closest to the target
        if (abs(v + sphere_volume(ndim, rk) - target) >= abs(v - target)) exit
      end if
      r = [r, rk]
      v = v + sphere_volume(ndim, rk)
    end do
    n = size(r)
    call sort_descending(r)
    allocate(spheres(4, n))
    call place(ndim, lo, hi, r, gap, .true., rng, spheres, ok)
    achieved = sum(sphere_volume(ndim, r)) / box
    if (.not. ok) why = 'could place only some of the ' // int_text(n) // ' spheres in ' &
      // int_text(max_tries) // ' tries each: lower the volume fraction, count or gap'

  contains

    real(wp) function draw_radius() result(x)
      integer :: tries
      select case (trim(distribution))
      case ('uniform')
        x = radius_min + (radius_max - radius_min) * rng_uniform(rng)
      case ('lognormal')
        do tries = 1, 1000
          x = radius * exp(sigma * rng_normal(rng))
          if ((radius_min <= 0.0_wp .or. x >= radius_min) .and. &
            (radius_max <= 0.0_wp .or. x <= radius_max)) return
        end do
        x = 0.0_wp
      case default
        x = radius
      end select
    end function draw_radius

  end subroutine random_spheres

  !> Random points in the box lo..hi, each at least spacing from every other (the seeds of
  !> Voronoi grains): random sequential addition of circles of diameter spacing whose
  !> centres may lie anywhere in the box.
  subroutine random_points(ndim, lo, hi, seed, n, spacing, points, ok)
    integer, intent(in) :: ndim, seed, n
    real(wp), intent(in) :: lo(3), hi(3), spacing
    real(wp), allocatable, intent(out) :: points(:, :)
    logical, intent(out) :: ok
    type(rng_t) :: rng
    real(wp), allocatable :: s(:, :)
    real(wp) :: r(n)
    call rng_seed(rng, seed)
    r = 0.5_wp * spacing
    allocate(s(4, n))
    call place(ndim, lo, hi, r, 0.0_wp, .false., rng, s, ok)
    points = s(1:3, :)
  end subroutine random_points

  !> Random sequential addition of spheres of radii r (largest first as given) into the box:
  !> a centre uniform in the box (inside: shrunk by radius and gap), accepted when it keeps
  !> gap from every sphere placed before; candidates are looked for in a grid of bins of
  !> size 2 max(r) + gap. ok is false when some sphere found no place in max_tries.
  subroutine place(ndim, lo, hi, r, gap, inside, rng, s, ok)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: lo(3), hi(3), r(:), gap
    logical, intent(in) :: inside
    type(rng_t), intent(inout) :: rng
    real(wp), intent(out) :: s(:, :)
    logical, intent(out) :: ok
    integer :: nb(3), k, tries, d, b(3), head_index
    integer, allocatable :: head(:), next(:)
    real(wp) :: bin, c(3), m, a(3), w(3)
    s = 0.0_wp
    ok = size(r) == 0
    if (ok) return
    bin = 2.0_wp * maxval(r) + max(gap, 0.0_wp)
    nb = 1
    nb(1:ndim) = max(1, min(int(1.0e6_wp**(1.0_wp / ndim)), int((hi(1:ndim) - lo(1:ndim)) / bin)))
    allocate(head(product(nb)), next(size(r)))
    head = 0
    next = 0
    do k = 1, size(r)
      m = 0.0_wp
      if (inside) m = r(k) + gap
      a = lo + m
      w = hi - lo - 2.0_wp * m
      ok = all(w(1:ndim) >= 0.0_wp)
      if (.not. ok) return
      do tries = 1, max_tries
        c = 0.0_wp
        do d = 1, ndim
          c(d) = a(d) + w(d) * rng_uniform(rng)
        end do
        if (free(c, r(k))) exit
      end do
      ok = tries <= max_tries
      if (.not. ok) return
      s(1:3, k) = c
      s(4, k) = r(k)
      b = bin_of(c)
      head_index = b(1) + nb(1) * (b(2) - 1 + nb(2) * (b(3) - 1))
      next(k) = head(head_index)
      head(head_index) = k
    end do

  contains

    function bin_of(x) result(ib)
      real(wp), intent(in) :: x(3)
      integer :: ib(3)
      ib = 1
      ib(1:ndim) = min(nb(1:ndim), max(1, 1 + int((x(1:ndim) - lo(1:ndim)) &
        / (hi(1:ndim) - lo(1:ndim)) * nb(1:ndim))))
    end function bin_of

    !> no sphere placed so far is closer than gap to the sphere (x, rx)
    logical function free(x, rx)
      real(wp), intent(in) :: x(3), rx
      integer :: ib(3), i, j, kk, e
      ib = bin_of(x)
      free = .false.
      do kk = max(1, ib(3) - 1), min(nb(3), ib(3) + 1)
        do j = max(1, ib(2) - 1), min(nb(2), ib(2) + 1)
          do i = max(1, ib(1) - 1), min(nb(1), ib(1) + 1)
            e = head(i + nb(1) * (j - 1 + nb(2) * (kk - 1)))
            do while (e > 0)
              if (norm2(x(1:ndim) - s(1:ndim, e)) < rx + s(4, e) + gap) return
              e = next(e)
            end do
          end do
        end do
      end do
      free = .true.
    end function free

  end subroutine place

  !> Signed distance from x to the union of the spheres (negative inside): exact, as the
  !> spheres do not overlap.
  pure real(wp) function spheres_distance(spheres, ndim, x) result(d)
    real(wp), intent(in) :: spheres(:, :)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: x(3)
    integer :: k
    d = huge(1.0_wp)
    do k = 1, size(spheres, 2)
      d = min(d, norm2(x(1:ndim) - spheres(1:ndim, k)) - spheres(4, k))
    end do
  end function spheres_distance

  !> r sorted largest first (equal radii keep their order)
  pure subroutine sort_descending(r)
    real(wp), intent(inout) :: r(:)
    real(wp) :: drawn(size(r))
    logical :: taken(size(r))
    integer :: k, i
    drawn = r
    taken = .false.
    do k = 1, size(r)
      i = maxloc(drawn, 1, .not. taken)
      r(k) = drawn(i)
      taken(i) = .true.
    end do
  end subroutine sort_descending

end module m_scene_generate
