!> The conservative cut-cell update of a phase with free surfaces (issue 15, manual/theory.md
!> section 7, manual/interfaces.md section 2c): the phase is updated on its own part of each
!> cell, alpha V, in the manner of Hu, Khoo, Adams and Huang (J. Comput. Phys. 219, 2006).
!> Its content C = alpha U (per cell volume) changes only by the face fluxes times the
!> faces' wet parts (m_euler with cut_faces_t); a free surface exchanges nothing (zero
!> traction, no mass crossing), so the phase's mass, momentum and energy change only by what
!> crosses the domain's sides. The ghost fill is kept for what it is good at: the states of
!> the reconstruction stencils.
!>
!> Between the stages of a step the phase's variables in q hold its content, so that the
!> halo exchange carries content; at the start of each later stage, and once after the last
!> one, cut_open turns content into states: the geometry from the level set (m_levelset_cut),
!> small cells (alpha < small) mixed with their largest face neighbour (the group takes the
!> mean state sum(C V) / sum(alpha V), which keeps every group's content), U = C / alpha.
!> Mixing needs the content and fractions three cells into the halo, which the four-deep
!> halo gives: every block mixes a group the same way, whoever owns it. Content that finds no
!> cell (a cell that the surface has left, with no neighbour to take it) is counted, not
!> hidden (stranded). A small cell alone on an open (outflow) side of the domain holds the
!> last of the phase leaving it: its content goes out through the side (cut%crossed).
!> Between steps q holds states and c0 the content they came from (a
!> wet cell whose centre lies outside the surface shows a ghost or rest state in q; its
!> content is in c0), alpha_n the fractions.
!> Built for one phase whose surfaces are all free (a solid in void, a base material with void
!> bodies); contacts between materials (MMI) and rigid bodies (MRI) still take the ghost-fluid
!> update and the conservation fix (issue 15, what is not built yet: manual/interfaces.md).
module m_gfm_cut
  use m_kinds, only: wp
  use m_layout, only: layout_t, cell_volume
  use m_blocks, only: block_t
  use m_phases, only: phases_t
  use m_state, only: i_rho, i_mx, i_mz, i_en, n_euler
  use m_euler, only: cut_faces_t, rk_blend
  use m_levelset_bodies, only: ls_set_t, ls_region, ls_material, ls_void
  use m_levelset_cut, only: levelset_cut
  implicit none
  private
  public :: cut_t, cut_setup, cut_geometry, cut_donate, cut_open, cut_update, cut_content
  public :: cut_strand

  !> A block's fractions over the padded block less its outer layer (for the mixing).
  type :: fraction_t
    real(wp), allocatable :: a(:, :, :)
  end type fraction_t

  !> The cut-cell state: which phase, its content and fractions per block.
  type :: cut_t
    logical :: on = .false.
    logical :: started = .false.                  !< c0 holds the content (the first step on)
    character(len=256) :: reason = ''
    integer :: p = 0                              !< the cut phase
    real(wp) :: small = 0.5_wp                    !< cells below this fraction are mixed
    type(cut_faces_t), allocatable :: faces(:)    !< (block) geometry of the current stage
    type(fraction_t), allocatable :: ext(:)       !< (block) its fractions into the halo
    real(wp), allocatable :: c(:, :, :, :, :)     !< (cell, variable, block) content, stage
    real(wp), allocatable :: c0(:, :, :, :, :)    !< (cell, variable, block) at the step start
    real(wp), allocatable :: alpha_n(:, :, :, :)  !< (cell, block) fractions of q's states
    real(wp) :: stranded(2) = 0.0_wp              !< mass, energy that found no cell (so far)
    real(wp) :: side(2, 3) = 0.0_wp               !< (mass, energy; stage) rates in at the sides
    real(wp) :: crossed(2) = 0.0_wp               !< mass, energy in through the sides (so far)
  end type cut_t

contains

  !> Decide whether the cut-cell update applies (mode 'cut_cell' asked for, one phase, every
  !> surface of it free) and size its arrays for the blocks of this rank.
  subroutine cut_setup(cut, asked, lay, ph, ls, blocks)
    type(cut_t), intent(inout) :: cut
    logical, intent(in) :: asked
    type(layout_t), intent(in) :: lay
    type(phases_t), intent(in) :: ph
    type(ls_set_t), intent(in) :: ls
    type(block_t), intent(in) :: blocks(:)
    integer :: n(3), b
    cut%on = .false.
    if (.not. asked) then
      cut%reason = "off: &numerics interface_update = 'ghost_fluid'"
      return
    end if
    if (ls%n == 0) then
      cut%reason = 'off: no level sets'
      return
    end if
    if (ph%nphase /= 1 .or. any(ls%kind /= ls_material .and. ls%kind /= ls_void)) then
      cut%reason = 'off: built for one phase with free surfaces only (no contact, no rigid ' &
        // 'body yet)'
      return
    end if
    cut%on = .true.
    cut%p = 1
    cut%reason = 'on: ' // trim(ph%material(1)) // ' with free surfaces'
    n = lay%nmax
    allocate(cut%c(n(1), n(2), n(3), ph%nflow, size(blocks)))
    allocate(cut%c0, mold=cut%c)
    allocate(cut%alpha_n(n(1), n(2), n(3), size(blocks)), cut%faces(size(blocks)))
    allocate(cut%ext(size(blocks)))
    cut%c = 0.0_wp
    cut%c0 = 0.0_wp
    cut%alpha_n = 0.0_wp
    do b = 1, size(blocks)
      n = blocks(b)%n
      allocate(cut%faces(b)%ax(0:n(1), n(2), n(3)), cut%faces(b)%ay(n(1), 0:n(2), n(3)), &
        cut%faces(b)%az(n(1), n(2), 0:n(3)), cut%faces(b)%alpha(n(1), n(2), n(3)), &
        cut%faces(b)%plane(n(1), n(2), n(3)))
    end do
  end subroutine cut_setup

  !> The geometry of the cut phase on block blk from its composite level set bigphi (over
  !> the padded block): the interior faces' apertures and fractions into cut%faces(b), and
  !> the fractions alpha_e over the padded block less its outer layer (for the mixing).
  subroutine cut_geometry(cut, b, blk, bigphi, open_side, alpha_e)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b
    type(block_t), intent(in) :: blk
    real(wp), intent(in) :: bigphi(:, :, :)
    logical, intent(in) :: open_side(2, 3)   !< the domain's outflow sides
    real(wp), allocatable, intent(out) :: alpha_e(:, :, :)
    real(wp), allocatable :: ax(:, :, :), ay(:, :, :), az(:, :, :), area(:, :, :)
    real(wp), allocatable :: normal(:, :, :, :), plane(:, :, :), phi(:, :, :)
    integer :: e(3), n(3), ne(3), g1(3), d, l, c
    real(wp) :: r0
    associate (lay => blk%lay)
      n = blk%n
      e = max(lay%ng - 1, 0)
      ! beyond an outflow side the level set continues linearly (the halo holds a copy of
      ! the edge cell): the side's faces then get the apertures the surface really has there
      phi = bigphi
      do d = 1, lay%ndim
        if (open_side(1, d) .and. blk%offset(d) == 0) then
          c = lay%ng(d) + 1
          do l = 1, lay%ng(d)
            call extend(d, c - l, c, c + 1, real(l, wp))
          end do
        end if
        if (open_side(2, d) .and. blk%offset(d) + n(d) == lay%cells(d)) then
          c = lay%ng(d) + n(d)
          do l = 1, lay%ng(d)
            call extend(d, c + l, c, c - 1, real(l, wp))
          end do
        end if
      end do
      ne = n + 2 * e
      g1 = merge(1, 0, lay%ng > 0)
      allocate(alpha_e(1-e(1):n(1)+e(1), 1-e(2):n(2)+e(2), 1-e(3):n(3)+e(3)))
      allocate(ax(-e(1):n(1)+e(1), 1-e(2):n(2)+e(2), 1-e(3):n(3)+e(3)))
      allocate(ay(1-e(1):n(1)+e(1), -e(2):n(2)+e(2), 1-e(3):n(3)+e(3)))
      allocate(az(1-e(1):n(1)+e(1), 1-e(2):n(2)+e(2), -e(3):n(3)+e(3)))
      allocate(area, plane, mold=alpha_e)
      allocate(normal(ne(1), ne(2), ne(3), 3))
      r0 = lay%lo(1) + real(blk%offset(1) - e(1), wp) * lay%dx(1)
      call levelset_cut(lay%ndim, lay%axisymmetric, ne, g1, lay%dx, r0, phi, ax, ay, az, &
        alpha_e, area, normal, plane)
      associate (f => cut%faces(b))
        f%ax = ax(0:n(1), 1:n(2), 1:n(3))
        f%ay = ay(1:n(1), 0:n(2), 1:n(3))
        f%az = az(1:n(1), 1:n(2), 0:n(3))
        f%alpha = alpha_e(1:n(1), 1:n(2), 1:n(3))
        f%plane = plane(1:n(1), 1:n(2), 1:n(3))
      end associate
    end associate

  contains

    !> layer `to` (an index of phi along d) = edge + l (edge - inner), the whole layer
    subroutine extend(dd, to, edge, inner, l)
      integer, intent(in) :: dd, to, edge, inner
      real(wp), intent(in) :: l
      select case (dd)
      case (1)
        phi(to, :, :) = phi(edge, :, :) + l * (phi(edge, :, :) - phi(inner, :, :))
      case (2)
        phi(:, to, :) = phi(:, edge, :) + l * (phi(:, edge, :) - phi(:, inner, :))
      case default
        phi(:, :, to) = phi(:, :, edge) + l * (phi(:, :, edge) - phi(:, :, inner))
      end select
    end subroutine extend
  end subroutine cut_geometry

  !> Content into states on block blk (number b), after the halo exchange: q's phase
  !> variables hold the content C over the padded block; the small cells are mixed, the
  !> interior's content kept in cut%c and its states U = C / alpha put into q. failed: a
  !> state with rho <= 0 or an energy that is not finite.
  subroutine cut_open(cut, b, blk, ph, alpha_e, open_side, final, failed)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b
    type(block_t), intent(inout) :: blk
    type(phases_t), intent(in) :: ph
    real(wp), intent(in) :: alpha_e(:, :, :)
    logical, intent(in) :: open_side(2, 3)   !< the domain's outflow sides (low, high; x, y, z)
    logical, intent(in) :: final             !< at the step's end (after its last stage)
    logical, intent(inout) :: failed
    integer, allocatable :: root(:, :, :, :)
    real(wp), allocatable :: vol(:), cq(:, :, :, :)
    integer :: e(3), n(3), i, j, k, r(3), lo, nf
    real(wp) :: sum_c(ph%nflow), sum_a, cc(ph%nflow)
    lo = ph%lo(cut%p)
    nf = ph%nflow
    associate (lay => blk%lay, q => blk%q)
      n = blk%n
      e = max(lay%ng - 1, 0)
      allocate(vol(1-e(1):n(1)+e(1)))
      do i = 1 - e(1), n(1) + e(1)
        vol(i) = cell_volume(lay, blk%offset, i)
      end do
      ! the content as it came (q's cells turn into states below, while groups still read it)
      allocate(cq(1-lay%ng(1):n(1)+lay%ng(1), 1-lay%ng(2):n(2)+lay%ng(2), &
        1-lay%ng(3):n(3)+lay%ng(3), nf))
      cq = q(:, :, :, lo:lo + nf - 1)
      call group_roots(lay, blk%offset, n, e, alpha_e, cut%small, root)
      do k = 1, n(3)
        do j = 1, n(2)
          do i = 1, n(1)
            r = root(:, i, j, k)
            if (.not. alpha(i, j, k) > 0.0_wp) then
              ! empty: what content it still holds found no wet neighbour (cut_donate); it
              ! is taken out (and counted) at the step's end only, where the budget sees it
              ! once (inside the step a stage's content counts with the stage's weight)
              cc = cq(i, j, k, :)
              if (final) then
                cut%stranded(1) = cut%stranded(1) + cq(i, j, k, i_rho) * vol(i)
                cut%stranded(2) = cut%stranded(2) + cq(i, j, k, i_en) * vol(i)
                cc = 0.0_wp
              end if
            else if (all(r == [i, j, k]) .and. .not. has_members(r)) then
              cc = cq(i, j, k, :)
              if (final .and. alpha(i, j, k) < cut%small .and. on_open_side([i, j, k])) then
                ! a small cell alone on an open side: the last of the phase leaving the
                ! domain; what it holds goes out through the side (counted)
                cut%crossed(1) = cut%crossed(1) - cc(i_rho) * vol(i)
                cut%crossed(2) = cut%crossed(2) - cc(i_en) * vol(i)
                cc = 0.0_wp
              end if
            else
              call group_sum(r, sum_c, sum_a)
              cc = alpha(i, j, k) * sum_c / sum_a
            end if
            cut%c(i, j, k, 1:nf, b) = cc
            if (alpha(i, j, k) > 0.0_wp .and. (cc(i_rho) > 0.0_wp .or. &
                alpha(i, j, k) >= cut%small)) then
              q(i, j, k, lo:lo + nf - 1) = cc / alpha(i, j, k)
              if (.not. admissible(q(i, j, k, lo:lo + nf - 1))) failed = .true.
            else
              ! no material (outside, or a small cell that nothing has reached yet): the
              ! state it had at the step's start (a ghost or rest state, which the ghost fill
              ! and m_gfm's rest state replace); its content is kept in cut%c
              q(i, j, k, lo:lo + nf - 1) = blk%q0(i, j, k, lo:lo + nf - 1)
            end if
          end do
        end do
      end do
    end associate

  contains

    real(wp) function alpha(i0, j0, k0)
      integer, intent(in) :: i0, j0, k0
      alpha = alpha_e(i0 + e(1), j0 + e(2), k0 + e(3))
    end function alpha

    !> whether cell c0 lies on an outflow side of the domain
    logical function on_open_side(c0) result(yes)
      integer, intent(in) :: c0(3)
      integer :: d
      yes = .false.
      do d = 1, blk%lay%ndim
        if (blk%offset(d) + c0(d) == 1 .and. open_side(1, d)) yes = .true.
        if (blk%offset(d) + c0(d) == blk%lay%cells(d) .and. open_side(2, d)) yes = .true.
      end do
    end function on_open_side

    !> whether some face neighbour of cell c0 has joined its group
    logical function has_members(c0) result(yes)
      integer, intent(in) :: c0(3)
      integer :: d, s, nb(3)
      yes = .false.
      do d = 1, blk%lay%ndim
        do s = -1, 1, 2
          nb = c0
          nb(d) = nb(d) + s
          if (all(root(:, nb(1), nb(2), nb(3)) == c0)) yes = .true.
        end do
      end do
    end function has_members

    !> The content (times volume) and wet volume of the group of root c0: c0 and the face
    !> neighbours that joined it.
    subroutine group_sum(c0, sc, sa)
      integer, intent(in) :: c0(3)
      real(wp), intent(out) :: sc(:), sa
      integer :: d, s, nb(3)
      sc = cq(c0(1), c0(2), c0(3), :) * vol(c0(1))
      sa = alpha(c0(1), c0(2), c0(3)) * vol(c0(1))
      do d = 1, blk%lay%ndim
        do s = -1, 1, 2
          nb = c0
          nb(d) = nb(d) + s
          if (.not. all(root(:, nb(1), nb(2), nb(3)) == c0)) cycle
          sc = sc + cq(nb(1), nb(2), nb(3), :) * vol(nb(1))
          sa = sa + alpha(nb(1), nb(2), nb(3)) * vol(nb(1))
        end do
      end do
    end subroutine group_sum

    logical function admissible(u)
      real(wp), intent(in) :: u(:)
      ! (the internal energy of a solid may be zero or below at its reference state)
      admissible = u(i_rho) > 0.0_wp .and. abs(u(i_en)) <= huge(1.0_wp)
    end function admissible
  end subroutine cut_open

  !> The root of each cell's mixing group, over the block and two cells into its halo:
  !> a cell with alpha >= small, or empty (alpha = 0), is its own root; a small cell joins
  !> its face neighbour of largest fraction (the first in -x, +x, -y, +y, -z, +z of equal
  !> ones) when that one is not small, else it stays its own root. Cells beyond the domain's
  !> sides take no part.
  subroutine group_roots(lay, offset, n, e, alpha_e, small, root)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), n(3), e(3)
    real(wp), intent(in) :: alpha_e(1-e(1):, 1-e(2):, 1-e(3):)
    real(wp), intent(in) :: small
    integer, allocatable, intent(out) :: root(:, :, :, :)
    integer :: w(3), i, j, k, best(3)
    w = min(e, 2)
    ! one more layer than w, so that a neighbour's root can be looked at
    allocate(root(3, -w(1):n(1)+w(1)+1, -w(2):n(2)+w(2)+1, -w(3):n(3)+w(3)+1))
    root = 0
    do k = 1 - w(3), n(3) + w(3)
      do j = 1 - w(2), n(2) + w(2)
        do i = 1 - w(1), n(1) + w(1)
          root(:, i, j, k) = [i, j, k]
          if (alpha_e(i, j, k) >= small .or. .not. alpha_e(i, j, k) > 0.0_wp) cycle
          if (.not. in_domain(lay, offset, [i, j, k])) cycle
          best = largest_neighbour(lay, offset, n, e, alpha_e, [i, j, k])
          if (best(1) == huge(1)) cycle
          if (alpha_e(best(1), best(2), best(3)) >= small) root(:, i, j, k) = best
        end do
      end do
    end do
  end subroutine group_roots

  !> Whether cell c (block coordinates) lies inside the domain.
  pure logical function in_domain(lay, offset, c) result(inside)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), c(3)
    integer :: d
    inside = .true.
    do d = 1, lay%ndim
      if (offset(d) + c(d) < 1 .or. offset(d) + c(d) > lay%cells(d)) inside = .false.
    end do
  end function in_domain

  !> The face neighbour of cell c inside the domain (and within alpha_e) with the largest
  !> fraction > 0, the first in -x, +x, -y, +y, -z, +z of equal ones; huge(1) when none.
  pure function largest_neighbour(lay, offset, n, e, alpha_e, c) result(best)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), n(3), e(3), c(3)
    real(wp), intent(in) :: alpha_e(1-e(1):, 1-e(2):, 1-e(3):)
    integer :: best(3), nb(3, 6), m, d
    real(wp) :: a(6)
    ! neighbour m: direction (m + 1) / 2, low side for odd m; -1 where there is none
    a = -1.0_wp
    do m = 1, 2 * lay%ndim
      d = (m + 1) / 2
      nb(:, m) = c
      nb(d, m) = c(d) + 2 * mod(m + 1, 2) - 1
      if (nb(d, m) < 1 - e(d) .or. nb(d, m) > n(d) + e(d)) cycle
      if (in_domain(lay, offset, nb(:, m))) a(m) = alpha_e(nb(1, m), nb(2, m), nb(3, m))
    end do
    best = huge(1)
    m = maxloc(a, 1)
    if (a(m) > 0.0_wp) best = nb(:, m)
  end function largest_neighbour

  !> The first pass of turning content into states, on block blk (number b) after the halo
  !> exchange: a cell the surface has left (alpha = 0) gives what content it still holds to
  !> its face neighbour of largest fraction; the interior's content afterwards goes into q
  !> (the caller exchanges it again before cut_open). Content with no wet neighbour stays
  !> (cut_open counts it as stranded).
  subroutine cut_donate(blk, ph, p, alpha_e)
    type(block_t), intent(inout) :: blk
    type(phases_t), intent(in) :: ph
    integer, intent(in) :: p
    real(wp), intent(in) :: alpha_e(:, :, :)
    real(wp), allocatable :: cq(:, :, :, :)
    integer :: e(3), n(3), i, j, k, d, s, nb(3), best(3), lo, nf
    lo = ph%lo(p)
    nf = ph%nflow
    associate (lay => blk%lay, q => blk%q)
      n = blk%n
      e = max(lay%ng - 1, 0)
      allocate(cq(1-lay%ng(1):n(1)+lay%ng(1), 1-lay%ng(2):n(2)+lay%ng(2), &
        1-lay%ng(3):n(3)+lay%ng(3), nf))
      cq = q(:, :, :, lo:lo + nf - 1)
      do k = 1, n(3)
        do j = 1, n(2)
          do i = 1, n(1)
            if (.not. alpha_at([i, j, k]) > 0.0_wp) then
              best = largest_neighbour(lay, blk%offset, n, e, alpha_e, [i, j, k])
              if (best(1) /= huge(1)) q(i, j, k, lo:lo + nf - 1) = 0.0_wp
              cycle
            end if
            ! what the emptied neighbours give this cell
            do d = 1, lay%ndim
              do s = -1, 1, 2
                nb = [i, j, k]
                nb(d) = nb(d) + s
                if (alpha_at(nb) > 0.0_wp) cycle
                if (.not. in_domain(lay, blk%offset, nb)) cycle
                best = largest_neighbour(lay, blk%offset, n, e, alpha_e, nb)
                ! content per cell volume: the volumes differ along r in axisymmetry
                if (all(best == [i, j, k])) q(i, j, k, lo:lo + nf - 1) = &
                  q(i, j, k, lo:lo + nf - 1) + cq(nb(1), nb(2), nb(3), :) &
                  * (cell_volume(lay, blk%offset, nb(1)) / cell_volume(lay, blk%offset, i))
              end do
            end do
          end do
        end do
      end do
    end associate

  contains

    real(wp) function alpha_at(c)
      integer, intent(in) :: c(3)
      alpha_at = alpha_e(c(1) + e(1), c(2) + e(2), c(3) + e(3))
    end function alpha_at
  end subroutine cut_donate

  !> After the stage update of block b: the phase's content C = a C0 + b (C + dt R) (the
  !> TVD Runge-Kutta weights of the stage), R the content rate that euler_rhs gave with the
  !> cut faces (in rhs), C0 the content at the step's start (the last open of the step
  !> before). The content goes into q's phase variables (interior), for the halo exchange
  !> before the next open.
  subroutine cut_update(cut, b, blk, ph, stage, order, dt)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b, stage, order
    type(block_t), intent(inout) :: blk
    type(phases_t), intent(in) :: ph
    real(wp), intent(in) :: dt
    real(wp) :: a
    integer :: lo, n(3)
    lo = ph%lo(cut%p)
    n = blk%n
    associate (c => cut%c(1:n(1), 1:n(2), 1:n(3), :, b), &
        c0 => cut%c0(1:n(1), 1:n(2), 1:n(3), :, b), r => blk%rhs(:, :, :, lo:lo + ph%nflow - 1))
      if (stage == 1) then
        c = c0 + dt * r
      else
        a = rk_blend(stage, order)
        c = a * c0 + (1.0_wp - a) * (c + dt * r)
      end if
      blk%q(1:n(1), 1:n(2), 1:n(3), lo:lo + ph%nflow - 1) = c
    end associate
  end subroutine cut_update

  !> A block that has fallen dormant (m_gfm: far from every surface) holds no phase: what
  !> content it still has is counted as stranded and set to zero.
  subroutine cut_strand(cut, b, blk)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b
    type(block_t), intent(in) :: blk
    integer :: i, n(3)
    real(wp) :: dv
    n = blk%n
    do i = 1, n(1)
      dv = cell_volume(blk%lay, blk%offset, i)
      cut%stranded(1) = cut%stranded(1) + sum(cut%c(i, 1:n(2), 1:n(3), i_rho, b)) * dv
      cut%stranded(2) = cut%stranded(2) + sum(cut%c(i, 1:n(2), 1:n(3), i_en, b)) * dv
    end do
    cut%c(:, :, :, :, b) = 0.0_wp
  end subroutine cut_strand

  !> The phase's mass, total energy and volume on block b: its content at the end of the last
  !> step (sum C V) and the volume its level set encloses (sum alpha V).
  function cut_content(cut, b, blk) result(me)
    type(cut_t), intent(in) :: cut
    integer, intent(in) :: b
    type(block_t), intent(in) :: blk
    real(wp) :: me(3)
    integer :: i, n(3)
    real(wp) :: dv
    n = blk%n
    me = 0.0_wp
    do i = 1, n(1)
      dv = cell_volume(blk%lay, blk%offset, i)
      me(1) = me(1) + sum(cut%c0(i, 1:n(2), 1:n(3), i_rho, b)) * dv
      me(2) = me(2) + sum(cut%c0(i, 1:n(2), 1:n(3), i_en, b)) * dv
      me(3) = me(3) + sum(cut%alpha_n(i, 1:n(2), 1:n(3), b)) * dv
    end do
  end function cut_content

end module m_gfm_cut
