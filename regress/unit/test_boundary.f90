!> Unit test of m_boundary's side conditions on one rank: every interior cell holds a code
!> of its global index (density positive), the halos a sentinel; after boundary_apply each
!> halo cell beyond a side of the domain must hold what the condition makes of its source
!> cell (halo cell n + l of cell n + 1 - l, outflow: of cell n):
!>   outflow   a copy;
!>   symmetry, rigid (and the face of an inactive obstacle block)   the mirror: normal
!>             velocity reversed, density, tangential velocity, internal energy, normal
!>             stresses and level sets kept, the shear stresses S_dt reversed;
!>   velocity  the same with normal velocity 2 V(t) - u, V(t) = V min(1, t / t_rise);
!> edges and corners (conditions of two sides) as the later direction makes of the earlier
!> one's halo; periodic sides and sides towards a neighbour block are left to m_halo
!> (untouched, and after halo_exchange they hold the periodic image); a skipped block takes
!> only the level sets (variables keep..nvar), none without keep; boundary_walls names the
!> reflecting sides and their wall velocities; bc_from_name maps the deck's names. Gas (5
!> variables), two solid phases (13 each) with a level set, 2D and 3D, one block and several.
program test_boundary
  use m_kinds, only: wp
  use m_layout, only: layout_t, layout_init, block_neighbor, wall_neighbor
  use m_blocks, only: block_t, blocks_allocate
  use m_boundary, only: bc_kind_t, bc_outflow, bc_symmetry, bc_rigid, bc_periodic, &
    bc_velocity, bc_from_name, boundary_apply, boundary_walls
  use m_halo, only: halo_plan_t, halo_plan_build, halo_exchange
  use m_state, only: n_euler, n_solid, i_rho, i_mx, i_en, stress_index
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_done, int_text
  implicit none
  real(wp), parameter :: sentinel = -7.0e30_wp, time = 1.0e-3_wp
  real(wp), parameter :: rel = 1.0e-13_wp
  type(bc_kind_t) :: bc
  logical, parameter :: none(3) = .false.
  call comm_init()
  call check_start('test_boundary')

  call check('bc_from_name outflow', bc_from_name('outflow') == bc_outflow)
  call check('bc_from_name symmetry', bc_from_name('symmetry') == bc_symmetry)
  call check('bc_from_name rigid', bc_from_name('rigid') == bc_rigid)
  call check('bc_from_name periodic', bc_from_name('periodic') == bc_periodic)
  call check('bc_from_name velocity', bc_from_name('velocity') == bc_velocity)

  ! 2D gas, one block: outflow / rigid low, symmetry / velocity high (steady wall)
  bc = bc_kind_t(lo=[bc_outflow, bc_rigid, bc_outflow], hi=[bc_symmetry, bc_velocity, &
    bc_outflow], velocity=[0.0_wp, -35.0_wp, 0.0_wp], rise_time=0.0_wp)
  call run_case('2d gas', 2, [16, 12, 1], [16, 12, 1], none, [integer ::], n_euler, 1, 0)

  ! 3D, two solid phases and a level set, one block; walls that move and ramp up
  bc = bc_kind_t(lo=[bc_velocity, bc_outflow, bc_symmetry], hi=[bc_rigid, bc_velocity, &
    bc_outflow], velocity=[120.0_wp, -80.0_wp, 0.0_wp], rise_time=4.0e-3_wp)
  call run_case('3d solid', 3, [8, 6, 10], [8, 6, 10], none, [integer ::], n_solid, 2, 1)

  ! 2D, 4 x 4 blocks, periodic in x, an obstacle block (rigid faces), outflow / velocity in y
  bc = bc_kind_t(lo=[bc_periodic, bc_outflow, bc_outflow], hi=[bc_periodic, bc_velocity, &
    bc_outflow], velocity=[0.0_wp, 10.0_wp, 0.0_wp], rise_time=0.0_wp)
  call run_case('2d blocks', 2, [32, 32, 1], [8, 8, 1], [.true., .false., .false.], [6], &
    n_euler, 1, 0)
  ! the same with a solid and a skipped block
  call run_case('2d blocks solid', 2, [32, 30, 1], [8, 8, 1], [.true., .false., .false.], &
    [11], n_solid, 1, 1)
  call check_done()

contains

  pure real(wp) function code(g, m)
    integer, intent(in) :: g(3), m
    code = 0.3_wp * real(m, wp) + 0.01_wp * (g(1) + 37 * g(2) + 1301 * g(3)) / 7.0_wp
    if (mod(m - 1, 13) == 0) code = 1.0_wp + 0.001_wp * (g(1) + 3 * g(2) + 5 * g(3))
  end function code

  !> nflow variables per phase, nphase phases, then nscalar level sets.
  subroutine run_case(tag, ndim, cells, bsize, periodic, holes, nflow, nphase, nscalar)
    character(len=*), intent(in) :: tag
    integer, intent(in) :: ndim, cells(3), bsize(3), holes(:), nflow, nphase, nscalar
    logical, intent(in) :: periodic(3)
    type(layout_t) :: lay
    type(block_t), allocatable :: blocks(:)
    type(halo_plan_t) :: plan
    logical, allocatable :: skip(:)
    integer :: nvar, b, keep
    real(wp), parameter :: lo(3) = 0.0_wp, hi(3) = 1.0_wp
    nvar = nflow * nphase + nscalar
    call layout_init(lay, ndim, cells, bsize, lo, hi, periodic, .false.)
    lay%active(holes) = .false.
    where (.not. lay%active) lay%owner = -1
    call blocks_allocate(lay, 0, nvar, blocks)
    call fill(blocks)
    call boundary_apply(lay, bc, blocks, nvar, nflow, time, nphase)
    call check_sides(tag, lay, blocks, nflow, nphase, 1, .false.)
    call check_walls(tag, lay, blocks)
    if (any(periodic)) then
      ! the pair as the solver calls it: neighbours' halos, then the sides
      call halo_plan_build(lay, blocks, plan)
      call halo_exchange(plan, blocks, nvar)
      call boundary_apply(lay, bc, blocks, nvar, nflow, time, nphase)
      call check_sides(tag // ' after halo_exchange', lay, blocks, nflow, nphase, 1, .true.)
      ! a skipped block takes only the level sets (keep = the first), none without keep
      allocate(skip(size(blocks)))
      skip = [(mod(b, 3) == 1, b = 1, size(blocks))]
      keep = nflow * nphase + 1
      call fill(blocks)
      if (nscalar > 0) then
        call boundary_apply(lay, bc, blocks, nvar, nflow, time, nphase, skip=skip, keep=keep)
      else
        call boundary_apply(lay, bc, blocks, nvar, nflow, time, nphase, skip=skip)
      end if
      do b = 1, size(blocks)
        if (skip(b)) then
          call check(tag // ' skip: flow variables of block ' // int_text(blocks(b)%id) // &
            ' untouched', untouched(blocks(b), keep - 1))
          if (nscalar > 0) call check_block(tag // ' skip, level sets', lay, blocks(b), &
            nflow, nphase, keep, .false.)
        else
          call check_block(tag // ' skip, other blocks', lay, blocks(b), nflow, nphase, 1, &
            .false.)
        end if
      end do
    end if
  end subroutine run_case

  !> Interior cells to their codes, halos to the sentinel.
  subroutine fill(blocks)
    type(block_t), intent(inout) :: blocks(:)
    integer :: b, i, j, k, m
    do b = 1, size(blocks)
      blocks(b)%q = sentinel
      do m = 1, size(blocks(b)%q, 4)
        do k = 1, blocks(b)%n(3)
          do j = 1, blocks(b)%n(2)
            do i = 1, blocks(b)%n(1)
              blocks(b)%q(i, j, k, m) = code(blocks(b)%offset + [i, j, k], m)
            end do
          end do
        end do
      end do
    end do
  end subroutine fill

  subroutine check_sides(tag, lay, blocks, nflow, nphase, m1, exchanged)
    character(len=*), intent(in) :: tag
    type(layout_t), intent(in) :: lay
    type(block_t), intent(in) :: blocks(:)
    integer, intent(in) :: nflow, nphase, m1
    logical, intent(in) :: exchanged
    integer :: b
    do b = 1, size(blocks)
      call check_block(tag, lay, blocks(b), nflow, nphase, m1, exchanged)
    end do
  end subroutine check_sides

  !> Every halo cell beyond side s of direction d of the block: for a domain side or an
  !> obstacle, inside along the later directions (which overwrite edges), anywhere along
  !> the earlier ones, what the condition makes of its source cell's final value; towards a
  !> neighbour block, inside along the others: the sentinel, or after the exchange the
  !> code of the (periodic) source cell.
  subroutine check_block(tag, lay, blk, nflow, nphase, m1, exchanged)
    character(len=*), intent(in) :: tag
    type(layout_t), intent(in) :: lay
    type(block_t), intent(in) :: blk
    integer, intent(in) :: nflow, nphase, m1
    logical, intent(in) :: exchanged
    integer :: d, s, kind, i, j, k, c(3), src(3), lo(3), hi(3), nbad, nvar, m, g(3)
    real(wp) :: vwall, want(size(blk%q, 4))
    character(len=16), parameter :: names(0:5) = [character(len=16) :: 'neighbour', &
      'outflow', 'symmetry', 'rigid', 'periodic', 'velocity']
    nvar = size(blk%q, 4)
    do d = 1, lay%ndim
      do s = -1, 1, 2
        call side_kind(lay, blk%id, d, s, kind, vwall)
        lo = 1 - lay%ng
        hi = blk%n + lay%ng
        if (kind == 0) then
          lo = 1
          hi = blk%n
        else
          lo(d + 1:) = 1
          hi(d + 1:) = blk%n(d + 1:)
        end if
        if (s < 0) then
          lo(d) = 1 - lay%ng(d)
          hi(d) = 0
        else
          lo(d) = blk%n(d) + 1
          hi(d) = blk%n(d) + lay%ng(d)
        end if
        nbad = 0
        do k = lo(3), hi(3)
          do j = lo(2), hi(2)
            do i = lo(1), hi(1)
              c = [i, j, k]
              if (kind == 0) then
                want = sentinel
                if (exchanged) then
                  g = modulo(blk%offset + c - 1, lay%cells) + 1
                  want = [(code(g, m), m = 1, nvar)]
                end if
                if (any(abs(blk%q(i, j, k, m1:) - want(m1:)) > 0.0_wp)) nbad = nbad + 1
                cycle
              end if
              src = c
              if (kind == bc_outflow) then
                src(d) = merge(1, blk%n(d), s < 0)
              else
                src(d) = merge(1 - c(d), 2 * blk%n(d) + 1 - c(d), s < 0)
              end if
              want = blk%q(src(1), src(2), src(3), :)
              if (kind /= bc_outflow) call mirror(want, nflow, nphase, d, vwall)
              if (.not. all(near(blk%q(i, j, k, m1:), want(m1:)))) nbad = nbad + 1
            end do
          end do
        end do
        call check(tag // ': block ' // int_text(blk%id) // ' direction ' // int_text(d) // &
          merge(' low  ', ' high ', s < 0) // trim(names(kind)) // ', ' // int_text(nbad) // &
          ' halo cells wrong', nbad == 0)
      end do
    end do
  end subroutine check_block

  !> The condition beyond a side, from the layout alone: 0 towards a neighbour block
  !> (periodic wrap included), rigid towards an obstacle, else the deck's; V(t) of a wall.
  subroutine side_kind(lay, id, d, s, kind, vwall)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id, d, s
    integer, intent(out) :: kind
    real(wp), intent(out) :: vwall
    integer :: dir(3), nbr
    dir = 0
    dir(d) = s
    nbr = block_neighbor(lay, id, dir)
    kind = merge(bc%lo(d), bc%hi(d), s < 0)
    if (nbr == wall_neighbor) kind = bc_rigid
    if (nbr > 0) kind = 0
    vwall = 0.0_wp
    if (kind == bc_velocity) then
      vwall = bc%velocity(d)
      if (bc%rise_time > 0.0_wp) vwall = vwall * min(1.0_wp, time / bc%rise_time)
    end if
  end subroutine side_kind

  !> The state a reflecting wall of normal d moving at vwall puts in the halo: normal
  !> velocity 2 vwall - u_d, same density, tangential velocity and internal energy; shear
  !> stresses S_dt (solids) reversed; level sets kept.
  subroutine mirror(w, nflow, nphase, d, vwall)
    real(wp), intent(inout) :: w(:)
    integer, intent(in) :: nflow, nphase, d
    real(wp), intent(in) :: vwall
    integer :: p, o, t
    real(wp) :: rho, un, ekin_t, eint
    do p = 1, nphase
      o = (p - 1) * nflow
      rho = w(o + i_rho)
      un = w(o + i_mx + d - 1) / rho
      ekin_t = 0.5_wp * sum(w(o + i_mx:o + i_mx + 2)**2) / rho**2 - 0.5_wp * un**2
      eint = w(o + i_en) / rho - ekin_t - 0.5_wp * un**2
      un = 2.0_wp * vwall - un
      w(o + i_mx + d - 1) = rho * un
      w(o + i_en) = rho * (eint + ekin_t + 0.5_wp * un**2)
      if (nflow == n_euler) cycle
      do t = 1, 3
        if (t /= d) w(o + stress_index(d, t)) = -w(o + stress_index(d, t))
      end do
    end do
  end subroutine mirror

  elemental logical function near(a, b)
    real(wp), intent(in) :: a, b
    near = abs(a - b) <= rel * max(abs(b), 1.0_wp)
  end function near

  !> Variables 1..m of every halo cell still hold the sentinel.
  logical function untouched(blk, m) result(yes)
    type(block_t), intent(in) :: blk
    integer, intent(in) :: m
    integer :: i, j, k
    yes = .true.
    do k = lbound(blk%q, 3), ubound(blk%q, 3)
      do j = lbound(blk%q, 2), ubound(blk%q, 2)
        do i = lbound(blk%q, 1), ubound(blk%q, 1)
          if (i >= 1 .and. i <= blk%n(1) .and. j >= 1 .and. j <= blk%n(2) .and. &
            k >= 1 .and. k <= blk%n(3)) cycle
          yes = yes .and. all(abs(blk%q(i, j, k, 1:m) - sentinel) <= 0.0_wp)
        end do
      end do
    end do
  end function untouched

  !> boundary_walls: reflecting exactly where the side is symmetry, rigid, velocity or an
  !> obstacle, with the wall velocity V(t) of a velocity side.
  subroutine check_walls(tag, lay, blocks)
    character(len=*), intent(in) :: tag
    type(layout_t), intent(in) :: lay
    type(block_t), intent(in) :: blocks(:)
    logical :: wall(2, 3), want
    real(wp) :: vwall(2, 3), v
    integer :: b, d, s, kind
    do b = 1, size(blocks)
      call boundary_walls(lay, bc, blocks(b), time, wall, vwall)
      do d = 1, lay%ndim
        do s = 1, 2
          call side_kind(lay, blocks(b)%id, d, 2 * s - 3, kind, v)
          want = kind == bc_symmetry .or. kind == bc_rigid .or. kind == bc_velocity
          call check(tag // ': boundary_walls of block ' // int_text(blocks(b)%id) // &
            ' side ' // int_text(s) // ' direction ' // int_text(d), &
            (wall(s, d) .eqv. want) .and. abs(vwall(s, d) - v) <= 0.0_wp)
        end do
      end do
    end do
  end subroutine check_walls

end program test_boundary
