!> Physical boundary conditions on the halo cells that no neighbour block fills
!> (manual/theory.md section 4): outflow (zero gradient), symmetry and rigid (mirror, normal
!> velocity reversed: inviscid slip wall), velocity (mirror with the normal velocity set to
!> 2 V(t) - u, V(t) = V min(1, t / t_rise)), and the wall of an inactive (rigid-obstacle)
!> block, which is rigid. Periodic sides are neighbour blocks, filled by m_halo (so both sides
!> of a direction are periodic or neither: bc_check, the deck's rule).
!> Order: first every halo box without a source block is filled by clamping to the nearest
!> interior cell (so that edges and corners hold admissible states), then the faces are
!> applied direction by direction over the full extent of the other directions, so edges
!> and corners at the domain boundary see the conditions of both sides.
module m_boundary
  use m_kinds, only: wp
  use m_text, only: choice_index, int_text
  use m_errors, only: rule_i
  use m_layout, only: layout_t, block_neighbor, wall_neighbor
  use m_blocks, only: block_t
  use m_state, only: i_rho, i_mx, i_en, n_solid, stress_index
  use m_halo, only: halo_plan_t, halo_exchange, halo_refresh, halo_exchange_finish, &
    halo_refresh_boxes
  use m_phases, only: phases_t
  implicit none
  private
  public :: bc_kind_t, bc_outflow, bc_symmetry, bc_rigid, bc_periodic, bc_velocity
  public :: bc_from_name, boundary_apply, boundary_walls, fill_ghosts, refresh_ghosts
  public :: ghosts_start, ghosts_finish
  public :: ghosts_all, ghosts_flow, ghosts_level_sets
  public :: bc_names, bc_check

  integer, parameter :: bc_outflow = 1, bc_symmetry = 2, bc_rigid = 3, bc_periodic = 4
  integer, parameter :: bc_velocity = 5
  !> the deck's names (&domain bc_lo, bc_hi): name k stands for condition k
  character(len=8), parameter :: bc_names(5) = [character(len=8) :: 'outflow', 'symmetry', &
    'rigid', 'periodic', 'velocity']

  !> the sets of variables whose ghost cells fill_ghosts fills
  integer, parameter :: ghosts_all = 0          !< flow of every phase and the level sets
  integer, parameter :: ghosts_flow = 1         !< flow of every phase
  integer, parameter :: ghosts_level_sets = 2   !< the level sets
  !> the halves of a split fill_ghosts (its `part`)
  integer, parameter :: ghosts_start = 1, ghosts_finish = 2

  !> The conditions on the six sides of the domain.
  type :: bc_kind_t
    integer :: lo(3) = bc_outflow, hi(3) = bc_outflow
    real(wp) :: velocity(3) = 0.0_wp
    real(wp) :: rise_time = 0.0_wp
    !> level sets continue linearly beyond an outflow side (else they are copied like the
    !> flow variables): the cut-cell update needs it, as a copied level set holds a surface
    !> near the side back and then lets it jump (manual/theory.md section 7c)
    logical :: linear_levelsets = .false.
  end type bc_kind_t

contains

  !> The deck's rule of the conditions bc_lo, bc_hi of the first ndim directions (m_deck_check
  !> hands its rule): periodic on both sides of a direction or on neither, since a periodic
  !> side's neighbour is the block at the other side.
  subroutine bc_check(bc_lo, bc_hi, ndim, rule)
    character(len=*), intent(in) :: bc_lo(3), bc_hi(3)
    integer, intent(in) :: ndim
    procedure(rule_i) :: rule
    character(len=:), allocatable :: dd
    logical :: lo_periodic, hi_periodic
    integer :: d
    do d = 1, ndim
      dd = '(' // int_text(d) // ')'
      lo_periodic = (bc_lo(d) == 'periodic')
      hi_periodic = (bc_hi(d) == 'periodic')
      call rule(lo_periodic .neqv. hi_periodic, 'domain ' // merge('bc_hi', 'bc_lo', &
        lo_periodic) // dd, 'periodic on one side only: bc_lo' // dd // " = '" &
        // trim(bc_lo(d)) // "' but bc_hi" // dd // " = '" // trim(bc_hi(d)) &
        // "' (both or neither must be 'periodic')")
    end do
  end subroutine bc_check

  !> The condition of a deck name (one of bc_names).
  integer function bc_from_name(name) result(k)
    character(len=*), intent(in) :: name
    k = choice_index(bc_names, name, 'bc_from_name')
  end function bc_from_name

  !> What lies beyond side s (-1 low, +1 high) of direction d of block id at time t:
  !> kind = 0 when a neighbour block fills the halo, else the condition (the face of an
  !> inactive obstacle block is rigid), with the wall's normal velocity for 'velocity' sides.
  subroutine side_condition(lay, bc, id, d, s, time, kind, vwall)
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    integer, intent(in) :: id, d, s
    real(wp), intent(in) :: time
    integer, intent(out) :: kind
    real(wp), intent(out) :: vwall
    integer :: nbr, dir(3)
    dir = 0
    dir(d) = s
    nbr = block_neighbor(lay, id, dir)
    vwall = 0.0_wp
    if (nbr > 0) then
      kind = 0
    else if (nbr == wall_neighbor) then
      kind = bc_rigid
    else if (s < 0) then
      kind = bc%lo(d)
    else
      kind = bc%hi(d)
    end if
    if (kind == bc_velocity) then
      vwall = bc%velocity(d)
      if (bc%rise_time > 0.0_wp) vwall = vwall * min(1.0_wp, time / bc%rise_time)
    end if
  end subroutine side_condition

  !> Halos of variables 1..nvar at the domain's sides; the first nphase (default 1) groups of
  !> nflow are the flow variables of each phase (the stress among them changes sign in a
  !> mirror), the others scalars (level sets). A block b with skip(b) set takes only
  !> variables keep..nvar (none without keep), as in m_halo's halo_exchange: the level sets
  !> of a dormant block. With `chosen`, the blocks b with chosen(b) set alone.
  subroutine boundary_apply(lay, bc, blocks, nvar, nflow, time, nphase, skip, keep, first, &
      chosen)
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: nvar, nflow
    real(wp), intent(in) :: time
    integer, intent(in), optional :: nphase
    logical, intent(in), optional :: skip(:)
    integer, intent(in), optional :: keep
    integer, intent(in), optional :: first   !< the first variable (default 1)
    logical, intent(in), optional :: chosen(:)
    integer :: b, d, s, kind, np, m1
    real(wp) :: vwall
    np = 1
    if (present(nphase)) np = nphase
    do b = 1, size(blocks)
      if (present(chosen)) then
        if (.not. chosen(b)) cycle
      end if
      m1 = 1
      if (present(first)) m1 = first
      if (present(skip)) then
        if (skip(b)) then
          if (present(keep)) then
            m1 = max(m1, keep)
          else
            m1 = nvar + 1
          end if
        end if
      end if
      if (m1 > nvar) cycle
      call clamp_fill(lay, blocks(b), m1, nvar)
      do d = 1, lay%ndim
        do s = -1, 1, 2
          call side_condition(lay, bc, blocks(b)%id, d, s, time, kind, vwall)
          if (kind /= 0) call face_fill(blocks(b)%lay, blocks(b)%q, m1, nvar, nflow, np, d, &
            s, kind, vwall, bc%linear_levelsets)
        end do
      end do
    end do
  end subroutine boundary_apply

  !> The reflecting sides of a block at time t: wall(s, d) is true where side s (1 low, 2 high)
  !> of direction d is a symmetry plane, a rigid or velocity wall, or the face of a rigid
  !> obstacle; vwall is the normal velocity of that wall. The flux kernels set the ghost-side
  !> face state to the mirror of the interior one there, so that mass and energy cross a
  !> symmetry plane exactly not at all, whatever the reconstruction did with round-off.
  subroutine boundary_walls(lay, bc, blk, time, wall, vwall)
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(block_t), intent(in) :: blk
    real(wp), intent(in) :: time
    logical, intent(out) :: wall(2, 3)
    real(wp), intent(out) :: vwall(2, 3)
    integer :: d, s, kind
    wall = .false.
    vwall = 0.0_wp
    do d = 1, lay%ndim
      do s = 1, 2
        call side_condition(lay, bc, blk%id, d, 2 * s - 3, time, kind, vwall(s, d))
        wall(s, d) = kind == bc_symmetry .or. kind == bc_rigid .or. kind == bc_velocity
      end do
    end do
  end subroutine boundary_walls

  !> Halo boxes with no source block take the value of the nearest interior cell, where no
  !> side condition writes over them (boundary_apply: the side conditions follow).
  subroutine clamp_fill(lay, blk, m1, nvar, clamped)
    type(layout_t), intent(in) :: lay
    type(block_t), intent(inout) :: blk
    integer, intent(in) :: m1, nvar
    logical, intent(out), optional :: clamped   !< some box was
    integer :: di, dj, dk, nbr, i, j, k, m, lo(3), hi(3), n(3), g(3), dmax(3)
    n = blk%n
    g = lay%ng
    dmax = merge(1, 0, g > 0)
    if (present(clamped)) clamped = .false.
    do dk = -dmax(3), dmax(3)
      do dj = -dmax(2), dmax(2)
        do di = -dmax(1), dmax(1)
          if (di == 0 .and. dj == 0 .and. dk == 0) cycle
          nbr = block_neighbor(lay, blk%id, [di, dj, dk])
          if (nbr > 0) cycle
          ! a box beyond a side of the domain (or a wall) in one of its directions is written
          ! over by that side's condition (face_fill, over the whole extent of the other
          ! directions, the directions in order, each reading only cells inside along its
          ! own): the final values never depend on a clamp there. Only a box whose faces all
          ! have neighbours (an inactive block across an edge or a corner) keeps the clamp.
          if (beyond_side([di, dj, dk])) cycle
          lo = merge(1 - g, merge(1, n + 1, [di, dj, dk] == 0), [di, dj, dk] < 0)
          hi = merge(0 * g, merge(n, n + g, [di, dj, dk] == 0), [di, dj, dk] < 0)
          if (present(clamped)) clamped = .true.
          do concurrent (m = m1:nvar, k = lo(3):hi(3), j = lo(2):hi(2), i = lo(1):hi(1))
            blk%q(i, j, k, m) = blk%q(min(max(i, 1), n(1)), min(max(j, 1), n(2)), &
              min(max(k, 1), n(3)), m)
          end do
        end do
      end do
    end do

  contains

    logical function beyond_side(dir) result(yes)
      integer, intent(in) :: dir(3)
      integer :: dd, e(3)
      yes = .false.
      do dd = 1, 3
        if (dir(dd) == 0) cycle
        e = 0
        e(dd) = dir(dd)
        yes = yes .or. block_neighbor(lay, blk%id, e) <= 0
      end do
    end function beyond_side

  end subroutine clamp_fill

  !> One face of a block (lay: its view, m_layout), side s (-1 low, +1 high) of direction d,
  !> over the full extent of the other directions including their halos, variables
  !> m1..nvar: halo cell n + l mirrors cell n + 1 - l (outflow: copies cell n; a level set,
  !> with linear_ls, takes cell n + l (cell n - cell n - 1) instead). The copy
  !> reads interior cells along d only, so it runs variable by variable; the mirror's sign
  !> changes follow per cell.
  subroutine face_fill(lay, q, m1, nvar, nflow, np, d, s, kind, vwall, linear_ls)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: m1, nvar, nflow, np, d, s, kind
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(in) :: vwall
    logical, intent(in) :: linear_ls   !< level sets (after np phases) continue linearly
    integer :: lo(3), hi(3), i, j, k, m, n, imom, p, o, is
    real(wp) :: rho, un_old, un_new
    logical :: linear
    n = lay%bsize(d)
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    if (s < 0) then
      hi(d) = 0
    else
      lo(d) = n + 1
    end if
    imom = i_mx + d - 1
    do m = m1, nvar
      ! a level set continues linearly beyond an outflow side
      linear = kind == bc_outflow .and. m > np * nflow .and. n > 1 .and. linear_ls
      do k = lo(3), hi(3)
        do j = lo(2), hi(2)
          select case (d)
          case (1)
            do i = lo(1), hi(1)
              is = source_cell(i)
              if (linear) then
                q(i, j, k, m) = q(is, j, k, m) + real(abs(i - is), wp) &
                  * (q(is, j, k, m) - q(inner_cell(), j, k, m))
              else
                q(i, j, k, m) = q(is, j, k, m)
              end if
            end do
          case (2)
            is = source_cell(j)
            call take_row(q(lo(1):hi(1), j, k, m), q(lo(1):hi(1), is, k, m), &
              q(lo(1):hi(1), inner_cell(), k, m), abs(j - is))
          case default
            is = source_cell(k)
            call take_row(q(lo(1):hi(1), j, k, m), q(lo(1):hi(1), j, is, m), &
              q(lo(1):hi(1), j, inner_cell(), m), abs(k - is))
          end select
        end do
      end do
    end do
    if (kind == bc_outflow) return
    do p = 1, min(np, nvar / nflow)
      o = (p - 1) * nflow
      if (o + 1 < m1) cycle
      do k = lo(3), hi(3)
        do j = lo(2), hi(2)
          do i = lo(1), hi(1)
            if (nflow >= n_solid) then
              ! mirror in direction d: the shear stresses S_dt change sign
              do m = 1, 3
                if (m == d) cycle
                q(i, j, k, o + stress_index(d, m)) = -q(i, j, k, o + stress_index(d, m))
              end do
            end if
            rho = q(i, j, k, o + i_rho)
            if (.not. abs(rho) > 0.0_wp) then
              ! no material (a cut-cell phase's content beyond its surface, m_gfm_cut)
              q(i, j, k, o + imom) = -q(i, j, k, o + imom)
              cycle
            end if
            un_old = q(i, j, k, o + imom) / rho
            un_new = 2.0_wp * vwall - un_old
            q(i, j, k, o + imom) = rho * un_new
            q(i, j, k, o + i_en) = q(i, j, k, o + i_en) + 0.5_wp * rho * (un_new**2 - un_old**2)
          end do
        end do
      end do
    end do

  contains

    !> the cell along d whose value halo cell x takes: the side's cell (outflow, and the
    !> level sets' linear continuation) or x's mirror image (every other kind)
    integer function source_cell(x) result(c)
      integer, intent(in) :: x
      if (kind == bc_outflow) then
        c = merge(1, n, s < 0)
      else
        c = merge(1 - x, 2 * n + 1 - x, s < 0)
      end if
    end function source_cell

    !> a halo row (y or z side) from its source row: a copy, or (linear) the source row
    !> continued by l times its difference from the row inside it
    subroutine take_row(row, src, inner, l)
      real(wp), intent(out) :: row(:)
      real(wp), intent(in) :: src(:), inner(:)
      integer, intent(in) :: l
      if (linear) then
        row = src + real(l, wp) * (src - inner)
      else
        row = src
      end if
    end subroutine take_row

    !> the second cell in from the side: the slope of the linear continuation
    integer function inner_cell() result(c)
      c = merge(2, n - 1, s < 0)
    end function inner_cell

  end subroutine face_fill

  !> The ghost cells of a set of variables (ghosts_all, ghosts_flow, ghosts_level_sets) on
  !> every block: the halo exchange (m_halo), then the side conditions of the domain. A block
  !> in skip (a dormant one, far from every surface) keeps its flow ghosts as they are and
  !> takes only its level sets', which always move. With `only`, block only alone: its flow
  !> halo from its neighbours on this rank (not changed since the last exchange), then all
  !> its side conditions; a block that wakes after being skipped. With `part`, one half of
  !> the fill, so that blocks can be worked on while the messages travel: ghosts_start
  !> starts the exchange and fills every ghost of the blocks that take nothing from other
  !> ranks (plan%remote(b) false), ghosts_finish (same set, time and skip) those of the
  !> others. The halves give what the whole gives: a block's side conditions read it alone.
  subroutine fill_ghosts(plan, lay, bc, blocks, ph, set, time, skip, only, part)
    type(halo_plan_t), intent(inout) :: plan
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(block_t), intent(inout) :: blocks(:)
    type(phases_t), intent(in) :: ph
    integer, intent(in) :: set
    real(wp), intent(in) :: time
    logical, intent(in), optional :: skip(:)
    integer, intent(in), optional :: only
    integer, intent(in), optional :: part
    integer :: first, last
    logical :: which(size(blocks))
    if (present(only)) then
      call halo_refresh(plan, blocks, only, ph%ils, 1)
      call boundary_apply(lay, bc, blocks(only:only), ph%nvar, ph%nflow, time, ph%nphase)
      return
    end if
    call ghost_variables(ph, set, first, last)
    which = .true.
    if (present(part)) which = plan%remote .eqv. (part == ghosts_finish)
    if (.not. present(part)) then
      call halo_exchange(plan, blocks, last, first, skip=skip, keep=ph%ils + 1)
    else if (part == ghosts_start) then
      call halo_exchange(plan, blocks, last, first, skip=skip, keep=ph%ils + 1, split=.true.)
    else
      call halo_exchange_finish(plan, blocks)
    end if
    call boundary_apply(lay, bc, blocks, last, ph%nflow, time, ph%nphase, skip=skip, &
      keep=ph%ils + 1, first=first, chosen=which)
  end subroutine fill_ghosts

  !> The flow ghosts again after the interiors of some blocks changed, block b in box(:, :, b)
  !> (empty: unchanged), on a rank whose blocks take nothing from other ranks: the local
  !> copies of what changed (m_halo's halo_refresh_boxes), then the side conditions of every
  !> block that took some or changed (they read the block alone); a block in skip neither.
  !> The halos end as fill_ghosts' flow set would leave them, at a fraction of its copies.
  subroutine refresh_ghosts(plan, lay, bc, blocks, ph, box, time, skip)
    type(halo_plan_t), intent(in) :: plan
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(block_t), intent(inout) :: blocks(:)
    type(phases_t), intent(in) :: ph
    integer, intent(in) :: box(:, :, :)
    real(wp), intent(in) :: time
    logical, intent(in) :: skip(:)
    integer :: touched(2, 3, size(blocks)), dirty(2, 3), b
    call halo_refresh_boxes(plan, blocks, box, ph%ils, 1, skip, touched)
    do b = 1, size(blocks)
      if (skip(b)) cycle
      dirty = touched(:, :, b)
      if (all(box(1, :, b) <= box(2, :, b))) then
        dirty(1, :) = min(dirty(1, :), box(1, :, b))
        dirty(2, :) = max(dirty(2, :), box(2, :, b))
      end if
      if (any(dirty(1, :) > dirty(2, :))) cycle
      call refresh_sides(lay, bc, blocks(b), ph%ils, ph%nflow, ph%nphase, time, dirty)
    end do
  end subroutine refresh_ghosts

  !> The side conditions of block blk again, variables 1..nvar, after the cells in dirty
  !> (padded coordinates: the interior cells it changed and the halo cells it took) changed:
  !> a side is filled again where the cells its fill reads (face_fill: along its direction
  !> the side's cell, or the ng cells that the mirror reflects, over the whole extent of the
  !> others) meet what changed, and what it wrote counts as changed for the sides after it.
  !> So the halos end as boundary_apply leaves them (which fills every side), at a fraction
  !> of its work where the change lies away from the domain's sides.
  subroutine refresh_sides(lay, bc, blk, nvar, nflow, np, time, dirty)
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(block_t), intent(inout) :: blk
    integer, intent(in) :: nvar, nflow, np
    real(wp), intent(in) :: time
    integer, intent(inout) :: dirty(2, 3)
    integer :: d, s, kind, n, g, reads(2), writes(2)
    real(wp) :: vwall
    logical :: clamped
    call clamp_fill(lay, blk, 1, nvar, clamped)
    ! (a clamped box lies in the extent that every side's fill reads)
    if (clamped) then
      dirty(1, :) = 1 - blk%lay%ng
      dirty(2, :) = blk%lay%bsize + blk%lay%ng
    end if
    do d = 1, lay%ndim
      do s = -1, 1, 2
        call side_condition(lay, bc, blk%id, d, s, time, kind, vwall)
        if (kind == 0) cycle
        n = blk%lay%bsize(d)
        g = blk%lay%ng(d)
        if (kind == bc_outflow) then
          reads = merge(1, n, s < 0)
        else if (s < 0) then
          reads = [1, g]
        else
          reads = [n + 1 - g, n]
        end if
        if (dirty(1, d) > reads(2) .or. dirty(2, d) < reads(1)) cycle
        call face_fill(blk%lay, blk%q, 1, nvar, nflow, np, d, s, kind, vwall, &
          bc%linear_levelsets)
        writes = merge([1 - g, 0], [n + 1, n + g], s < 0)
        dirty(1, d) = min(dirty(1, d), writes(1))
        dirty(2, d) = max(dirty(2, d), writes(2))
      end do
    end do
  end subroutine refresh_sides

  !> The variables first..last of a set of fill_ghosts.
  pure subroutine ghost_variables(ph, set, first, last)
    type(phases_t), intent(in) :: ph
    integer, intent(in) :: set
    integer, intent(out) :: first, last
    first = 1
    last = ph%nvar
    if (set == ghosts_flow) last = ph%ils
    if (set == ghosts_level_sets) first = ph%ils + 1
  end subroutine ghost_variables

end module m_boundary
