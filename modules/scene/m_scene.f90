!> The scene: bodies and their shapes (DESIGN section 6, &body), painted in deck order onto
!> the cells of the blocks (a later body overrides an earlier one): which cells a body holds,
!> its signed distance (the initial level set of a body of another material, void or rigid;
!> manual/interfaces.md), and whether a rigid body covers whole blocks (which are then not
!> computed and act as exact rigid walls for their neighbours, m_boundary), and the motion of
!> a moving rigid body, whose level set is its distance at the time of each stage; whether
!> the boxes of a material tile the domain, and which state of a material the scene takes
!> from the material itself (state_needs: m_deck_check asks for it). The
!> generated shapes (random spheres, a random field, Voronoi grains: manual/scenes.md) are
!> made once at set-up by scene_generate into a made_t per body (the deck's body_t holds
!> only what the deck says), on every rank alike; each is one body, with one level set, but
!> grains one level set per colour (body_distance's colour). body_check
!> holds the deck's rules for a body's shape and generator values (m_deck_check calls it).
module m_scene
  use m_kinds, only: wp
  use m_config, only: body_t, is_set
  use m_errors, only: stop_collective, error_line, rule_i
  use m_text, only: int_text, real_text, got_text
  use m_scene_generate, only: random_spheres, spheres_distance
  use m_scene_field, only: random_field, field_distance, field_points, max_field_points
  use m_scene_grains, only: grains_t, make_grains, grains_distance
  use m_layout, only: layout_t, block_offset, block_extent
  use m_blocks, only: block_t
  use m_levelset_bodies, only: ls_set_t, ls_rigid
  implicit none
  private
  public :: inside_body, cell_centre, rigid_block_status, body_distance, rigid_bodies_move
  public :: boxes_cover, state_needs, scene_generate, body_check, made_t

  !> What scene_generate made of a body (nothing for a plain shape).
  type :: made_t
    real(wp), allocatable :: spheres(:, :)    !< (1:3, k) centre, (4, k) radius of sphere k
    real(wp), allocatable :: field(:, :, :)   !< signed distance on the field's grid over lo..hi
    type(grains_t) :: grains                  !< Voronoi grains, a level set per colour
    real(wp) :: fraction = 0.0_wp             !< the volume fraction of the box it made
  end type made_t

contains

  pure function cell_centre(lay, offset, i, j, k) result(x)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), i, j, k
    real(wp) :: x(3)
    x = lay%lo + (real(offset + [i, j, k], wp) - 0.5_wp) * lay%dx
  end function cell_centre

  !> Why the scene takes the state of the material called name from the material itself (''
  !> where it does not): rho0 (p0) where no body gives it, that is a body of it without rho
  !> (without p or T), the base material outside boxes of it that tile the domain, and every
  !> phase of a scene with level sets; a temperature for a body of it given by T (why_t is
  !> left as it was otherwise).
  subroutine state_needs(bodies, name, base, ndim, lo, hi, why_rho, why_p, why_t)
    type(body_t), intent(in) :: bodies(:)
    character(len=*), intent(in) :: name, base
    integer, intent(in) :: ndim
    real(wp), intent(in) :: lo(3), hi(3)
    character(len=:), allocatable, intent(out) :: why_rho, why_p
    character(len=:), allocatable, intent(inout) :: why_t
    integer :: i
    why_rho = ''
    if (any(bodies%material /= base)) why_rho = 'the rest state of a scene with level sets'
    ! (the boxes of the base material only set its initial state)
    if (name == base .and. .not. boxes_cover(bodies, name, ndim, lo, hi)) &
      why_rho = 'the base material outside its bodies'
    why_p = why_rho
    do i = 1, size(bodies)
      associate(b => bodies(i))
        if (b%material /= name) cycle
        if (is_set(b%T)) why_t = "body '" // trim(b%name) // "', given by T"
        if (.not. is_set(b%rho)) why_rho = "body '" // trim(b%name) // "' without rho"
        if (.not. is_set(b%p) .and. .not. is_set(b%T)) &
          why_p = "body '" // trim(b%name) // "' without p or T"
      end associate
    end do
  end subroutine state_needs

  !> Whether the boxes among bodies that are of material `material` cover the domain lo..hi
  !> (its first ndim directions): the centre of every cell of the grid that the boxes' faces
  !> make is inside one (strictly, unlike inside_body).
  pure logical function boxes_cover(bodies, material, ndim, lo, hi) result(covered)
    type(body_t), intent(in) :: bodies(:)
    character(len=*), intent(in) :: material
    integer, intent(in) :: ndim
    real(wp), intent(in) :: lo(3), hi(3)
    real(wp), allocatable :: e(:)
    real(wp) :: x(2 * size(bodies) + 2, 3), p(3)
    integer :: n(3), d, i, j, k, b
    logical :: box(size(bodies))
    box = bodies%material == material .and. bodies%shape == 'box'
    n = 1
    x = 0.0_wp
    do d = 1, ndim
      e = [lo(d), hi(d)]
      do b = 1, size(bodies)
        if (box(b)) e = [e, bodies(b)%lo(d), bodies(b)%hi(d)]
      end do
      e = max(lo(d), min(hi(d), e))
      n(d) = 0
      do i = 1, size(e)   ! the centre of the span from each edge to the next
        if (.not. any(e > e(i))) cycle
        n(d) = n(d) + 1
        x(n(d), d) = 0.5_wp * (e(i) + minval(e, e > e(i)))
      end do
    end do
    covered = .false.
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          p = [x(i, 1), x(j, 2), x(k, 3)]
          if (.not. any([(box(b) .and. all(p(1:ndim) > bodies(b)%lo(1:ndim) .and. &
            p(1:ndim) < bodies(b)%hi(1:ndim)), b = 1, size(bodies))])) return
        end do
      end do
    end do
    covered = .true.
  end function boxes_cover

  !> Is point x (only its first ndim coordinates count) inside the body?
  pure logical function inside_body(body, made, ndim, x) result(inside)
    type(body_t), intent(in) :: body
    type(made_t), intent(in) :: made
    integer, intent(in) :: ndim
    real(wp), intent(in) :: x(3)
    real(wp) :: r(3), a(3), along
    r = 0.0_wp
    r(1:ndim) = x(1:ndim) - body%center(1:ndim)
    select case (trim(body%shape))
    case ('box')
      inside = all(x(1:ndim) >= body%lo(1:ndim) .and. x(1:ndim) <= body%hi(1:ndim))
    case ('sphere')
      inside = sum(r**2) <= body%radius**2
    case ('cylinder')
      a = body%axis / norm2(body%axis)
      along = dot_product(r, a)
      inside = abs(along) <= 0.5_wp * body%length .and. &
        sum((r - along * a)**2) <= body%radius**2
    case ('half_space')
      inside = dot_product(r, body%axis) <= 0.0_wp
    case ('random_spheres', 'random_field', 'grains')
      inside = body_distance(body, made, ndim, x) <= 0.0_wp
    case default
      inside = .false.
    end select
  end function inside_body

  !> Signed distance from point x to the body's surface (negative inside; only the first ndim
  !> coordinates count): exact for spheres, half spaces, boxes, finite cylinders and random
  !> spheres, so the level sets start as signed distances; a random field's is its grid's
  !> distance interpolated, clipped by the box; grains', that of the grains of one colour
  !> (colour > 0) or of all (m_scene_grains).
  pure real(wp) function body_distance(body, made, ndim, x, colour) result(d)
    type(body_t), intent(in) :: body
    type(made_t), intent(in) :: made
    integer, intent(in) :: ndim
    real(wp), intent(in) :: x(3)
    integer, intent(in), optional :: colour
    real(wp) :: r(3), a(3), along, side(3)
    r = 0.0_wp
    r(1:ndim) = x(1:ndim) - body%center(1:ndim)
    select case (trim(body%shape))
    case ('box')
      side = 0.0_wp
      side(1:ndim) = abs(x(1:ndim) - 0.5_wp * (body%lo(1:ndim) + body%hi(1:ndim))) &
        - 0.5_wp * (body%hi(1:ndim) - body%lo(1:ndim))
      d = box_distance(side(1:ndim))
    case ('sphere')
      d = norm2(r) - body%radius
    case ('cylinder')
      a = body%axis / norm2(body%axis)
      along = dot_product(r, a)
      d = box_distance([norm2(r - along * a) - body%radius, abs(along) - 0.5_wp * body%length])
    case ('half_space')
      d = dot_product(r, body%axis) / norm2(body%axis)
    case ('random_spheres')
      d = spheres_distance(made%spheres, ndim, x)
    case ('random_field')
      d = field_distance(made%field, ndim, body%lo, body%hi, x)
    case ('grains')
      if (present(colour)) then
        d = grains_distance(made%grains, ndim, body%lo, body%hi, colour, x)
      else
        d = grains_distance(made%grains, ndim, body%lo, body%hi, 0, x)
      end if
    case default
      d = huge(1.0_wp)
    end select
  end function body_distance

  !> Signed distance of a point whose distances outside each face pair of a box are side(:)
  !> (negative inside along that axis).
  pure real(wp) function box_distance(side) result(d)
    real(wp), intent(in) :: side(:)
    d = norm2(max(side, 0.0_wp)) + min(maxval(side), 0.0_wp)
  end function box_distance

  !> Make the generated shapes of the bodies (random spheres, a random field, grains) from
  !> their deck variables; every rank makes the same (the same arithmetic on the same seed,
  !> no communication: manual/scenes.md). g: the ghost band (a length) that grains of one
  !> colour keep apart. A scene that cannot be made stops every rank with the body's name
  !> and what to change (deck: the deck file's name for the message).
  subroutine scene_generate(bodies, ndim, g, deck, made)
    type(body_t), intent(in) :: bodies(:)
    type(made_t), allocatable, intent(out) :: made(:)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: g
    character(len=*), intent(in) :: deck
    character(len=:), allocatable :: why
    integer :: b
    allocate(made(size(bodies)))
    do b = 1, size(bodies)
      associate (body => bodies(b), m => made(b))
        select case (trim(body%shape))
        case ('random_spheres')
          call random_spheres(ndim, body%lo, body%hi, body%seed, body%volume_fraction, &
            body%count, body%size_distribution, body%radius, body%radius_min, &
            body%radius_max, body%radius_sigma, body%gap, m%spheres, m%fraction, why)
        case ('random_field')
          call random_field(ndim, body%lo, body%hi, body%seed, body%correlation_length, &
            body%volume_fraction, m%field, m%fraction, why)
        case ('grains')
          call make_grains(ndim, body%lo, body%hi, body%seed, body%count, &
            body%volume_fraction, g, m%grains, m%fraction, why, body%colours)
        case default
          cycle
        end select
        call stop_collective(error_line(deck, '&body shape', "'" // trim(body%shape) &
          // "' in body '" // trim(body%name) // "': " // why, ''), len(why) == 0)
      end associate
    end do
  end subroutine scene_generate

  !> For block id: 0 when no cell centre lies in the rigid body, 2 when all do, 1 when only
  !> some do (a rigid body must cover whole blocks in this version).
  integer function rigid_block_status(lay, id, body, made) result(status)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id
    type(body_t), intent(in) :: body
    type(made_t), intent(in) :: made
    integer :: i, j, k, off(3), nin, n(3)
    off = block_offset(lay, id)
    n = block_extent(lay, id)
    nin = 0
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          if (inside_body(body, made, lay%ndim, cell_centre(lay, off, i, j, k))) nin = nin + 1
        end do
      end do
    end do
    status = 1
    if (nin == 0) status = 0
    if (nin == product(n)) status = 2
  end function rigid_block_status

  !> The level sets (variables ils + l) of the moving rigid bodies at time t on every cell of
  !> the blocks, halo included: each body's distance, moved by its velocity times t.
  subroutine rigid_bodies_move(lay, bodies, made, ls, ils, blocks, t)
    type(layout_t), intent(in) :: lay
    type(body_t), intent(in) :: bodies(:)
    type(made_t), intent(in) :: made(:)
    type(ls_set_t), intent(in) :: ls
    integer, intent(in) :: ils
    type(block_t), intent(inout) :: blocks(:)
    real(wp), intent(in) :: t
    integer :: b, l, i, j, k
    do l = 1, ls%n
      if (ls%kind(l) /= ls_rigid .or. .not. any(abs(ls%velocity(:, l)) > 0.0_wp)) cycle
      do b = 1, size(blocks)
        associate (q => blocks(b)%q, body => bodies(ls%body(l)))
          do k = lbound(q, 3), ubound(q, 3)
            do j = lbound(q, 2), ubound(q, 2)
              do i = lbound(q, 1), ubound(q, 1)
                q(i, j, k, ils + l) = body_distance(body, made(ls%body(l)), lay%ndim, &
                  cell_centre(lay, blocks(b)%offset, i, j, k) - t * ls%velocity(:, l))
              end do
            end do
          end do
        end associate
      end do
    end do
  end subroutine rigid_bodies_move

  !> Body b's shape and generator values as deck rules (rule, m_errors' rule_i; in_b names
  !> the body in a message, " in body 'ball'"): what each shape needs, and what random
  !> sequential addition or the field's grid cannot do (manual/scenes.md).
  subroutine body_check(b, ndim, in_b, rule)
    type(body_t), intent(in) :: b
    integer, intent(in) :: ndim
    character(len=*), intent(in) :: in_b
    procedure(rule_i) :: rule
    character(len=:), allocatable :: what, dist
    real(wp) :: rmax, jam
    integer :: d
    logical :: generated
    generated = b%shape == 'random_spheres' .or. b%shape == 'random_field' .or. &
      b%shape == 'grains'
    what = 'must be > 0 for a ' // trim(b%shape) // in_b
    do d = 1, ndim
      call rule((b%shape == 'box' .or. generated) .and. .not. b%hi(d) > b%lo(d), 'body hi(' &
        // int_text(d) // ')', 'must be > lo(' // int_text(d) // ') = ' // real_text(b%lo(d)) &
        // in_b // got_text(b%hi(d)))
    end do
    call rule((b%shape == 'sphere' .or. b%shape == 'cylinder') .and. .not. &
      b%radius > 0.0_wp, 'body radius', what // got_text(b%radius))
    if (generated) call generator_check()
    call rule(b%colours > 0 .and. b%shape /= 'grains', 'body colours', 'is for grains only' &
      // in_b // got_text(b%colours))
    call rule(b%shape == 'cylinder' .and. .not. b%length > 0.0_wp, 'body length', what &
      // got_text(b%length))
    call rule((b%shape == 'cylinder' .or. b%shape == 'half_space') .and. .not. &
      maxval(abs(b%axis)) > 0.0_wp, 'body axis', 'must not be zero for a ' // trim(b%shape) &
      // in_b)

  contains

    subroutine generator_check()
      dist = trim(b%size_distribution)
      if (b%shape == 'random_field') then
        call rule(.not. b%volume_fraction > 0.0_wp, 'body volume_fraction', 'must be > 0 ' &
          // 'for a random_field (the share of the box below the threshold)' // in_b)
        call rule(.not. b%correlation_length > 0.0_wp, 'body correlation_length', &
          'must be > 0 for a random_field' // in_b // got_text(b%correlation_length))
        if (b%correlation_length > 0.0_wp .and. all(b%hi(1:ndim) > b%lo(1:ndim))) &
          call rule(product(real(field_points(ndim, b%lo, b%hi, b%correlation_length), &
          wp)) > max_field_points, 'body correlation_length', 'too small for the box' // in_b &
          // ': the field has 8 grid points per correlation length and at most 2^22 (raise' &
          // ' it or shrink lo..hi)' // got_text(b%correlation_length))
        return
      end if
      if (b%shape == 'grains') then
        call rule(.not. b%count > 1, 'body count', 'must be > 1 for grains (the number of ' &
          // 'grains)' // in_b // got_text(b%count))
        call rule(.not. (b%volume_fraction > 0.0_wp .and. b%volume_fraction < 1.0_wp), &
          'body volume_fraction', 'must be in (0, 1) for grains (their share of the box, ' &
          // 'the rest binder)' // in_b // got_text(b%volume_fraction))
        return
      end if
      call rule(b%count == 0 .and. .not. b%volume_fraction > 0.0_wp, 'body volume_fraction', &
        'give volume_fraction > 0 or count > 0 for random_spheres' // in_b)
      call rule(b%count > 0 .and. b%volume_fraction > 0.0_wp, 'body count', &
        'give count or volume_fraction' // in_b // ', not both')
      call rule(dist /= 'uniform' .and. .not. b%radius > 0.0_wp, 'body radius', 'must be > 0 ' &
        // 'for a ' // dist // ' size_distribution' // in_b // got_text(b%radius))
      call rule(dist == 'uniform' .and. .not. b%radius_min > 0.0_wp, 'body radius_min', &
        'must be > 0 for a uniform size_distribution' // in_b // got_text(b%radius_min))
      call rule(dist == 'uniform' .and. .not. b%radius_max > b%radius_min, 'body radius_max', &
        'must be > radius_min = ' // real_text(b%radius_min) // ' for a uniform ' &
        // 'size_distribution' // in_b // got_text(b%radius_max))
      call rule(dist == 'lognormal' .and. .not. b%radius_sigma > 0.0_wp, 'body radius_sigma', &
        'must be > 0 for a lognormal size_distribution' // in_b // got_text(b%radius_sigma))
      call rule(dist == 'lognormal' .and. b%radius_min > 0.0_wp .and. b%radius_max > 0.0_wp &
        .and. .not. b%radius_max > b%radius_min, 'body radius_max', 'must be > radius_min = ' &
        // real_text(b%radius_min) // in_b // got_text(b%radius_max))
      rmax = b%radius
      if (dist == 'uniform' .or. (dist == 'lognormal' .and. b%radius_max > 0.0_wp)) &
        rmax = b%radius_max
      call rule(any(2.0_wp * (rmax + b%gap) > b%hi(1:ndim) - b%lo(1:ndim)) .and. &
        all(b%hi(1:ndim) > b%lo(1:ndim)), 'body radius', 'a sphere of the largest ' &
        // 'radius ' // real_text(rmax) // ' with its gap does not fit in lo..hi' // in_b)
      ! random sequential addition jams at about 0.547 of the area (2D), 0.38 of the volume
      jam = merge(0.5_wp, merge(0.35_wp, 0.9_wp, ndim == 3), ndim == 2)
      call rule(b%volume_fraction > jam, 'body volume_fraction', 'must be <= ' &
        // real_text(jam) // in_b // ': spheres placed one by one jam near 0.55 of the area ' &
        // '(2D), 0.38 of the volume (3D)' // got_text(b%volume_fraction))
    end subroutine generator_check

  end subroutine body_check

end module m_scene
