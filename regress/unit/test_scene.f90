!> Unit test of the scene generators (m_scene_generate, m_scene_field; manual/scenes.md):
!> the random numbers against the reference xoshiro256** stream; random spheres the same
!> from the same seed, at the volume fraction asked within one sphere, apart by the gap and
!> inside the box, in 2D and 3D and with each size distribution; the Gaussian random field
!> the same from the same seed, at its fraction on its grid and within 1 % on a finer
!> raster, a signed distance; Voronoi grains whose binder fills the asked fraction, and a
!> colouring of 1024 grains in which no two grains of a colour come within the ghost band
!> (checked by brute force on 64 grains). Prints the numbers manual/scenes.md quotes.
program test_scene
  use m_kinds, only: wp, i8
  use m_comm, only: comm_init
  use m_scene_generate, only: rng_t, rng_next, rng_seed, rng_uniform, random_spheres, &
    sphere_volume, spheres_distance, random_points
  use m_scene_grains, only: grain_distance, binder_thickness, grain_conflicts, colour_graph, &
    make_grains, grains_distance, grains_t
  use m_scene_field, only: random_field, field_distance
  use m_test_check, only: check_start, check, check_close, check_done, int_text
  implicit none
  real(wp), parameter :: um = 1.0e-6_wp
  call comm_init()
  call check_start('scene_unit')
  call random_numbers()
  call spheres()
  call field()
  call grains()
  call grain_bodies()
  call check_done()

contains

  !> xoshiro256** from the state (1, 2, 3, 4): the reference C code's first twelve outputs
  !> (the last ones with the top bit set, which the additions on halves must carry right)
  subroutine random_numbers()
    type(rng_t) :: a, b
    integer(i8) :: r, expected(12)
    integer :: k
    real(wp) :: u, v, lo, hi
    logical :: ok
    expected = [11520_i8, 0_i8, 1509978240_i8, 1215971899390074240_i8, &
      1216172134540287360_i8, 607988272756665600_i8, -2273821095074991991_i8, &
      8476171486693032832_i8, -7851629734111992839_i8, 2904607092377533576_i8, &
      -3974627880268122080_i8, 1266835380287703300_i8]
    a%s = [1_i8, 2_i8, 3_i8, 4_i8]
    do k = 1, 12
      call rng_next(a, r)
      call check('xoshiro256** output ' // int_text(k), r == expected(k))
    end do
    call rng_seed(a, 42)
    call rng_seed(b, 42)
    lo = 1.0_wp
    hi = 0.0_wp
    ok = .true.
    do k = 1, 10000
      u = rng_uniform(a)
      lo = min(lo, u)
      hi = max(hi, u)
      v = rng_uniform(b)
      if (.not. same([u], [v])) ok = .false.
    end do
    call check('same seed, same numbers', ok)
    call check('uniform in [0, 1)', lo >= 0.0_wp .and. hi < 1.0_wp .and. hi - lo > 0.99_wp)
  end subroutine random_numbers

  subroutine spheres()
    real(wp), allocatable :: s(:, :), s2(:, :)
    real(wp) :: f, f2
    character(len=:), allocatable :: why
    real(wp) :: lo(3), hi(3)
    lo = 0.0_wp
    hi = [100.0_wp, 100.0_wp, 0.0_wp] * um
    ! the random-void scene: 10 um voids at 20 %, 1 um apart
    call random_spheres(2, lo, hi, 7, 0.2_wp, 0, 'fixed', 5.0_wp * um, 0.0_wp, 0.0_wp, &
      0.0_wp, 1.0_wp * um, s, f, why)
    call check('fixed 2D: made (' // why // ')', len(why) == 0)
    print '(a, i0, a, f7.4)', '  fixed 2D, target 0.2: ', size(s, 2), ' circles, fraction ', f
    call check_close('fixed 2D: fraction within half a circle', f, 0.2_wp, &
      0.5_wp * sphere_volume(2, 5.0_wp * um) / 1.0e-8_wp)
    call check_close('fixed 2D: fraction = their area', f, &
      sum(sphere_volume(2, s(4, :))) / 1.0e-8_wp, 1.0e-12_wp)
    call apart(s, 2, lo, hi, 1.0_wp * um, 'fixed 2D')
    call random_spheres(2, lo, hi, 7, 0.2_wp, 0, 'fixed', 5.0_wp * um, 0.0_wp, 0.0_wp, &
      0.0_wp, 1.0_wp * um, s2, f2, why)
    call check('fixed 2D: the same seed, the same circles', &
      same(pack(s, .true.), pack(s2, .true.)))
    call random_spheres(2, lo, hi, 8, 0.2_wp, 0, 'fixed', 5.0_wp * um, 0.0_wp, 0.0_wp, &
      0.0_wp, 1.0_wp * um, s2, f2, why)
    call check('fixed 2D: another seed, other circles', &
      .not. same(pack(s, .true.), pack(s2, .true.)))
    ! uniform radii 3..7 um at 25 %
    call random_spheres(2, lo, hi, 3, 0.25_wp, 0, 'uniform', 0.0_wp, 3.0_wp * um, &
      7.0_wp * um, 0.0_wp, 0.5_wp * um, s, f, why)
    call check('uniform 2D: made (' // why // ')', len(why) == 0)
    print '(a, i0, a, f7.4)', '  uniform 2D, target 0.25: ', size(s, 2), ' circles, fraction ', f
    call check_close('uniform 2D: fraction within half the largest circle', f, 0.25_wp, &
      0.5_wp * sphere_volume(2, 7.0_wp * um) / 1.0e-8_wp)
    call check('uniform 2D: radii in range', all(s(4, :) >= 3.0_wp * um .and. &
      s(4, :) <= 7.0_wp * um))
    call apart(s, 2, lo, hi, 0.5_wp * um, 'uniform 2D')
    ! lognormal, median 4 um, sigma 0.3, kept in 2..8 um, at 15 %
    call random_spheres(2, lo, hi, 5, 0.15_wp, 0, 'lognormal', 4.0_wp * um, 2.0_wp * um, &
      8.0_wp * um, 0.3_wp, 0.5_wp * um, s, f, why)
    call check('lognormal 2D: made (' // why // ')', len(why) == 0)
    print '(a, i0, a, f7.4)', '  lognormal 2D, target 0.15: ', size(s, 2), &
      ' circles, fraction ', f
    call check_close('lognormal 2D: fraction within half the largest circle', f, 0.15_wp, &
      0.5_wp * sphere_volume(2, 8.0_wp * um) / 1.0e-8_wp)
    call check('lognormal 2D: radii in range', all(s(4, :) >= 2.0_wp * um .and. &
      s(4, :) <= 8.0_wp * um))
    call apart(s, 2, lo, hi, 0.5_wp * um, 'lognormal 2D')
    ! 100 particles of 0.75 mm in a 30 x 30 mm part of the channel
    call random_spheres(2, [15.0e-3_wp, 0.0_wp, 0.0_wp], [45.0e-3_wp, 30.0e-3_wp, 0.0_wp], 1, &
      0.0_wp, 100, 'fixed', 0.75e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.5e-3_wp, s, f, why)
    call check('count 2D: 100 made', len(why) == 0 .and. size(s, 2) == 100)
    call apart(s, 2, [15.0e-3_wp, 0.0_wp, 0.0_wp], [45.0e-3_wp, 30.0e-3_wp, 0.0_wp], &
      0.5e-3_wp, 'count 2D')
    ! 3D: spheres of 0.05 at 20 % of a unit cube
    call random_spheres(3, [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], 11, 0.2_wp, 0, &
      'fixed', 0.05_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.005_wp, s, f, why)
    call check('fixed 3D: made (' // why // ')', len(why) == 0)
    print '(a, i0, a, f7.4)', '  fixed 3D, target 0.2: ', size(s, 2), ' spheres, fraction ', f
    call check_close('fixed 3D: fraction within half a sphere', f, 0.2_wp, &
      0.5_wp * sphere_volume(3, 0.05_wp))
    call apart(s, 3, [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], 0.005_wp, 'fixed 3D')
    call check_close('fixed 3D: distance at a centre is -r', spheres_distance(s, 3, s(1:3, 1)), &
      -s(4, 1), 1.0e-15_wp)
    ! too full to place
    call random_spheres(2, lo, hi, 1, 0.7_wp, 0, 'fixed', 5.0_wp * um, 0.0_wp, 0.0_wp, &
      0.0_wp, 1.0_wp * um, s, f, why)
    call check('70 % of circles: refused with a reason', len(why) > 0)
  end subroutine spheres

  !> every pair of spheres and every sphere and the box faces at least gap apart
  subroutine apart(s, ndim, lo, hi, gap, what)
    real(wp), intent(in) :: s(:, :), lo(3), hi(3), gap
    integer, intent(in) :: ndim
    character(len=*), intent(in) :: what
    real(wp) :: worst
    integer :: i, j
    worst = huge(1.0_wp)
    do i = 1, size(s, 2)
      do j = i + 1, size(s, 2)
        worst = min(worst, norm2(s(1:ndim, i) - s(1:ndim, j)) - s(4, i) - s(4, j))
      end do
      worst = min(worst, minval(s(1:ndim, i) - s(4, i) - lo(1:ndim)), &
        minval(hi(1:ndim) - s(1:ndim, i) - s(4, i)))
    end do
    call check(what // ': no overlap, gap kept', worst >= gap * (1.0_wp - 1.0e-12_wp))
  end subroutine apart

  subroutine field()
    real(wp), allocatable :: d(:, :, :), d2(:, :, :)
    real(wp) :: f, f2, lo(3), hi(3), x(3), h, jump
    character(len=:), allocatable :: why
    integer :: i, j, nin, m
    lo = 0.0_wp
    hi = [100.0_wp, 100.0_wp, 0.0_wp] * um
    call random_field(2, lo, hi, 3, 5.0_wp * um, 0.2_wp, d, f, why)
    call check('field 2D: made (' // why // ')', len(why) == 0)
    call check('field 2D: grid of 8 points per correlation length', all(shape(d) == &
      [160, 160, 1]))
    call check_close('field 2D: fraction on its grid', f, 0.2_wp, 1.0_wp / size(d))
    call random_field(2, lo, hi, 3, 5.0_wp * um, 0.2_wp, d2, f2, why)
    call check('field 2D: the same seed, the same field', &
      same(pack(d, .true.), pack(d2, .true.)))
    call random_field(2, lo, hi, 4, 5.0_wp * um, 0.2_wp, d2, f2, why)
    call check('field 2D: another seed, another field', &
      .not. same(pack(d, .true.), pack(d2, .true.)))
    ! on a raster 3 times finer than the field's grid
    m = 480
    nin = 0
    do j = 1, m
      do i = 1, m
        x = [(i - 0.5_wp) / m, (j - 0.5_wp) / m, 0.0_wp] * hi
        if (field_distance(d, 2, lo, hi, x) < 0.0_wp) nin = nin + 1
      end do
    end do
    print '(a, f7.4, a, f7.4)', '  field 2D, target 0.2: grid ', f, ', raster 480^2 ', &
      real(nin, wp) / m**2
    call check_close('field 2D: fraction on a finer raster within 0.01', real(nin, wp) / m**2, &
      0.2_wp, 0.01_wp)
    ! a distance: neighbours differ by at most the spacing, and by nearly that somewhere
    h = 100.0_wp * um / 160.0_wp
    jump = max(maxval(abs(d(2:, :, 1) - d(:159, :, 1))), maxval(abs(d(:, 2:, 1) - d(:, :159, 1))))
    call check_close('field 2D: |grad d| <= 1 (largest jump / spacing)', jump / h, 1.0_wp, &
      0.02_wp)
    call check('field 2D: inside and outside both reach a few spacings', minval(d) < -2 * h &
      .and. maxval(d) > 2 * h)
    ! 3D
    call random_field(3, [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], 9, 0.2_wp, &
      0.3_wp, d, f, why)
    call check('field 3D: made', len(why) == 0 .and. all(shape(d) == [40, 40, 40]))
    call check_close('field 3D: fraction on its grid', f, 0.3_wp, 1.0_wp / size(d))
    print '(a, f7.4)', '  field 3D, target 0.3: grid ', f
  end subroutine field

  subroutine grains()
    real(wp), allocatable :: c(:, :)
    logical, allocatable :: conflict(:, :)
    integer, allocatable :: colour(:)
    real(wp) :: lo(3), hi(3), t, g, x(3), worst, vb
    integer :: ncol, i, j, k, a, nbinder, m, p, q
    logical :: ok
    integer, allocatable :: owner(:, :)
    lo = 0.0_wp
    hi = [1.0_wp, 1.0_wp, 0.0_wp]
    ! 1024 grains (32 x 32 on average) in a unit square; the PBX's 96.44 % HMX by mass
    ! (binder 1.0, HMX 1.9 g/cc: 6.6 % binder by volume), a ghost band of 4 cells of a
    ! 320-cell mesh
    call random_points(2, lo, hi, 1, 1024, 0.6_wp / 32.0_wp, c, ok)
    call check('1024 seeds placed', ok .and. size(c, 2) == 1024)
    vb = (0.0356_wp / 1.0_wp) / (0.0356_wp / 1.0_wp + 0.9644_wp / 1.9_wp)
    call binder_thickness(c, 2, lo, hi, vb, 1.0_wp / 320.0_wp, t)
    g = 4.0_wp / 320.0_wp
    print '(a, f7.4, a, es10.3, a, es10.3)', '  grains: binder volume fraction ', vb, &
      ', thickness ', t, ', ghost band ', g
    call grain_conflicts(c, 2, lo, hi, t, g, conflict)
    allocate(colour(1024))
    call colour_graph(conflict, colour, ncol)
    print '(a, i0, a, i0)', '  1024 grains: colours ', ncol, ', most conflicts of a grain ', &
      maxval(count(conflict, 1))
    call check('1024 grains: at most 8 colours', ncol <= 8)
    ok = .true.
    do i = 1, 1024
      ok = ok .and. .not. any(conflict(:, i) .and. colour == colour(i))
    end do
    call check('1024 grains: no conflicting pair shares a colour', ok)
    ! 64 grains, by brute force on a raster: binder fraction and the colouring
    call random_points(2, lo, hi, 2, 64, 0.6_wp / 8.0_wp, c, ok)
    call binder_thickness(c, 2, lo, hi, 0.1_wp, 1.0_wp / 400.0_wp, t)
    g = 0.03_wp
    call grain_conflicts(c, 2, lo, hi, t, g, conflict)
    deallocate(colour)
    allocate(colour(64))
    call colour_graph(conflict, colour, ncol)
    m = 200
    allocate(owner(m, m))
    nbinder = 0
    do j = 1, m
      do i = 1, m
        x = [(i - 0.5_wp) / m, (j - 0.5_wp) / m, 0.0_wp]
        owner(i, j) = 0
        do a = 1, 64
          if (grain_distance(c, a, 2, lo, hi, t, x) < 0.0_wp) owner(i, j) = a
        end do
        if (owner(i, j) == 0) nbinder = nbinder + 1
      end do
    end do
    print '(a, f7.4, a, i0)', '  64 grains: binder fraction 0.1 -> ', real(nbinder, wp) / m**2, &
      ', colours ', ncol
    call check_close('64 grains: binder fraction within 0.01', real(nbinder, wp) / m**2, &
      0.1_wp, 0.01_wp)
    ! the closest two raster points of grains of one colour (less the raster's diagonal)
    worst = huge(1.0_wp)
    do j = 1, m
      do i = 1, m
        if (owner(i, j) == 0) cycle
        do q = max(1, j - 10), min(m, j + 10)
          do p = max(1, i - 10), min(m, i + 10)
            k = owner(p, q)
            if (k == 0 .or. k == owner(i, j)) cycle
            if (colour(k) /= colour(owner(i, j))) cycle
            worst = min(worst, norm2(real([p - i, q - j], wp)) / m)
          end do
        end do
      end do
    end do
    call check('64 grains: grains of one colour at least the ghost band apart', &
      worst + sqrt(2.0_wp) / m >= g)
  end subroutine grains

  !> A body of 1024 grains as the solver makes it (make_grains): its fraction, its colours,
  !> and the level set of each colour by the near seeds and bins against the brute-force
  !> minimum of grain_distance over the grains of that colour, at 100 random points and
  !> 100 of a raster: the same within the ghost band (to round-off), the same sign
  !> everywhere, and never above cap. The PBX deck's scale: 10 mm at 10 um, band 6 cells.
  subroutine grain_bodies()
    type(grains_t) :: gr
    type(rng_t) :: rng
    character(len=:), allocatable :: why
    real(wp) :: lo(3), hi(3), g, achieved, x(3), fast, slow, worst
    integer :: k, a, col, wrong
    lo = 0.0_wp
    hi = [1.0_wp, 1.0_wp, 0.0_wp]
    g = 6.0_wp / 1000.0_wp
    call make_grains(2, lo, hi, 1, 1024, 0.9396_wp, g, gr, achieved, why)
    print '(a, f7.4, a, i0, a, es10.3)', '  grain body: fraction ', achieved, ', colours ', &
      gr%ncolour, ', binder thickness ', gr%thickness
    call check('grain body made', len(why) == 0 .and. size(gr%seed, 2) == 1024)
    call check_close('grain body: fraction 0.9396 within 0.005', achieved, 0.9396_wp, 0.005_wp)
    call check('grain body: at most 8 colours', gr%ncolour <= 8)
    call rng_seed(rng, 7)
    worst = 0.0_wp
    wrong = 0
    do k = 1, 200
      x = [rng_uniform(rng), rng_uniform(rng), 0.0_wp]
      if (k > 100) x = [(mod(k, 10) + 0.5_wp) / 10.0_wp, (k / 10 - 9.5_wp) / 10.0_wp, 0.0_wp]
      do col = 0, gr%ncolour
        slow = huge(1.0_wp)
        do a = 1, 1024
          if (col == 0 .or. gr%colour(a) == col) &
            slow = min(slow, grain_distance(gr%seed, a, 2, lo, hi, gr%thickness, x))
        end do
        fast = grains_distance(gr, 2, lo, hi, col, x)
        if (slow < g) worst = max(worst, abs(fast - slow))
        if ((fast < 0.0_wp .neqv. slow < 0.0_wp) .or. fast > gr%cap) wrong = wrong + 1
      end do
    end do
    print '(a, es10.3, a, i0)', '  grain body: largest difference within the band ', worst, &
      ', points of the wrong sign or above cap ', wrong
    call check('grain body: level sets exact within the band', worst < 1.0e-12_wp)
    call check('grain body: the sign right everywhere, never above cap', wrong == 0)
    ! &body colours: the same grains dealt into fewer level sets, the band's need kept
    col = gr%ncolour
    call make_grains(2, lo, hi, 1, 1024, 0.9396_wp, g, gr, achieved, why, max_colours=2)
    call check('grain body, colours = 2: two level sets, every grain in one of them', &
      gr%ncolour == 2 .and. all(gr%colour >= 1 .and. gr%colour <= 2))
    call check('grain body, colours = 2: the colours the band needs still reported', &
      gr%needed == col .and. col > 2)
    call make_grains(2, lo, hi, 1, 1024, 0.9396_wp, g, gr, achieved, why, max_colours=8)
    call check('grain body, colours = 8: no cut where the band needs fewer', &
      gr%ncolour == col .and. gr%needed == col)
  end subroutine grain_bodies

  !> the same bits (reals compared without a tolerance; arrays of any rank by pack)
  pure logical function same(a, b)
    real(wp), intent(in) :: a(:), b(:)
    same = size(a) == size(b) .and. all(transfer(a, [0_i8]) == transfer(b, [0_i8]))
  end function same

end program test_scene
