!> The per-cell rules of the cut-cell update (issue 15, manual/theory.md section 7): where a
!> cell stands (inside the domain, on an outflow side), which neighbour it joins or gives to
!> (largest_neighbour, group_roots), the density of the full cells beside it (full_density),
!> the mixing of small cells that no group holds (mix_lonely), and the exchange of content
!> where cells fill or empty between steps (cut_donate). The stage update that uses them is
!> m_gfm_cut.
module m_gfm_cut_cells
  use m_kinds, only: wp, i8
  use m_layout, only: layout_t, cell_volume
  use m_blocks, only: block_t
  use m_phases, only: phases_t
  use m_state, only: i_rho, i_epsp, i_wcold
  use m_gfm_cut_work, only: fit_work
  implicit none
  private
  public :: full, debt_mark, full_density, group_roots, ring, on_open, in_domain
  public :: largest_neighbour, cut_donate, mix_lonely

  !> a cell's fraction from which it counts as full of its phase
  real(wp), parameter :: full = 1.0_wp - 1.0e-12_wp
  !> the fraction group_roots is given for a wet cell in debt (its fluxes drew out more mass
  !> than it held, m_gfm_cut): the smallest of small cells, which joins but is never joined
  real(wp), parameter :: debt_mark = tiny(1.0_wp)

contains

  !> The mean density of the full cells (alpha = 1) of the phase other than c within one
  !> cell of c, else within two (inside the domain and the fractions' reach); 0 when none.
  !> rho_q: the density (mass content) over the padded block.
  function full_density(lay, offset, e, alpha_e, rho_q, c) result(rho)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), e(3), c(3)
    real(wp), intent(in) :: alpha_e(1-e(1):, 1-e(2):, 1-e(3):)
    real(wp), intent(in) :: rho_q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp) :: rho, total
    integer :: reach, lo(3), hi(3), i, j, k, count
    rho = 0.0_wp
    do reach = 1, 2
      lo = c
      hi = c
      lo(1:lay%ndim) = max(c(1:lay%ndim) - reach, lbound(alpha_e) + [0, 0, 0])
      hi(1:lay%ndim) = min(c(1:lay%ndim) + reach, ubound(alpha_e) + [0, 0, 0])
      total = 0.0_wp
      count = 0
      do k = lo(3), hi(3)
        do j = lo(2), hi(2)
          do i = lo(1), hi(1)
            if (all([i, j, k] == c)) cycle
            if (.not. alpha_e(i, j, k) >= full) cycle
            if (.not. in_domain(lay, offset, [i, j, k])) cycle
            total = total + rho_q(i, j, k)
            count = count + 1
          end do
        end do
      end do
      if (count > 0) then
        rho = total / real(count, wp)
        return
      end if
    end do
  end function full_density

  !> The root of each cell's mixing group, over the block and two cells into its halo:
  !> a cell with alpha >= small, or empty (alpha = 0), is its own root; a small cell joins
  !> its face neighbour of largest fraction (the first in -x, +x, -y, +y, -z, +z of equal
  !> ones) when that one is not small, else its edge or corner neighbour of largest
  !> fraction that is not small (a cell in the crook of a surface, whose face neighbours are
  !> small cells of another group: where two voids' remnants meet), else (a sheet of small
  !> cells, or a cell in debt, debt_mark) its ring neighbour of highest rank where that one
  !> outranks its own ring, else it stays its own root. A group is thus a root and members
  !> within one cell of it (any direction), so that every block forms it alike from two
  !> cells of halo. Cells beyond the domain's sides take no part.
  subroutine group_roots(lay, offset, n, e, alpha_e, small, root)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), n(3), e(3)
    real(wp), intent(in) :: alpha_e(1-e(1):, 1-e(2):, 1-e(3):)
    real(wp), intent(in) :: small
    integer, allocatable, intent(inout) :: root(:, :, :, :)   !< (kept from call to call)
    integer :: w(3), i, j, k, best(3), top(3)
    w = min(e, 2)
    ! one more layer than w, so that a neighbour's root can be looked at
    call fit_work(root, [1, -w(1), -w(2), -w(3)], [3, n(1)+w(1)+1, n(2)+w(2)+1, n(3)+w(3)+1])
    root = 0
    do k = 1 - w(3), n(3) + w(3)
      do j = 1 - w(2), n(2) + w(2)
        do i = 1 - w(1), n(1) + w(1)
          root(:, i, j, k) = [i, j, k]
          if (alpha_e(i, j, k) >= small .or. .not. alpha_e(i, j, k) > 0.0_wp) cycle
          if (.not. in_domain(lay, offset, [i, j, k])) cycle
          best = largest_neighbour(lay, offset, n, e, alpha_e, [i, j, k])
          if (best(1) == huge(1)) cycle
          if (.not. alpha_e(best(1), best(2), best(3)) >= small) &
            best = largest_neighbour(lay, offset, n, e, alpha_e, [i, j, k], corners=.true.)
          if (best(1) == huge(1)) cycle
          if (alpha_e(best(1), best(2), best(3)) >= small) root(:, i, j, k) = best
        end do
      end do
    end do
    ! a small cell with no cell to join in its ring (a sheet of small cells, thinner than a
    ! cell), or in debt (debt_mark), joins its ring neighbour of highest rank (fraction, then place)
    ! where that one outranks its own ring: a root of small cells, which joins nobody (every
    ! cell of its ring is smaller). A block decides it alike for every cell whose group its
    ! interior reads: a cell of the second halo layer joins a root of the first only if that
    ! root's ring lies within alpha_e.
    do k = 1 - w(3), n(3) + w(3)
      do j = 1 - w(2), n(2) + w(2)
        do i = 1 - w(1), n(1) + w(1)
          if (.not. (alpha_e(i, j, k) > 0.0_wp .and. alpha_e(i, j, k) < small)) cycle
          if (.not. all(root(:, i, j, k) == [i, j, k])) cycle
          if (.not. in_domain(lay, offset, [i, j, k])) cycle
          best = top_of_ring([i, j, k])
          if (best(1) == huge(1)) cycle
          if (.not. alpha_e(best(1), best(2), best(3)) > debt_mark) cycle
          if (any(best(1:lay%ndim) - 1 < 1 - e(1:lay%ndim) &
            .or. best(1:lay%ndim) + 1 > n(1:lay%ndim) + e(1:lay%ndim))) cycle
          top = top_of_ring(best)
          if (top(1) == huge(1)) cycle
          if (outranks(best, top)) root(:, i, j, k) = best
        end do
      end do
    end do

  contains

    !> the wet ring neighbour of c inside the domain and within alpha_e of highest rank;
    !> huge(1) when none
    function top_of_ring(c) result(t)
      integer, intent(in) :: c(3)
      integer :: t(3), nb(3, 26), l, nl
      call ring(lay%ndim, c, nb, nl)
      t = huge(1)
      do l = 1, nl
        if (any(nb(:, l) < 1 - e .or. nb(:, l) > n + e)) cycle
        if (.not. in_domain(lay, offset, nb(:, l))) cycle
        if (.not. alpha_e(nb(1, l), nb(2, l), nb(3, l)) > 0.0_wp) cycle
        if (t(1) == huge(1)) then
          t = nb(:, l)
        else if (outranks(nb(:, l), t)) then
          t = nb(:, l)
        end if
      end do
    end function top_of_ring

    !> whether cell a ranks above cell b: a larger fraction, or the same and a later place in
    !> the whole grid (z, then y, then x), so that every block ranks cells alike
    logical function outranks(a, b)
      integer, intent(in) :: a(3), b(3)
      integer :: ga(3), gb(3), d
      outranks = alpha_e(a(1), a(2), a(3)) > alpha_e(b(1), b(2), b(3))
      if (outranks .or. alpha_e(a(1), a(2), a(3)) < alpha_e(b(1), b(2), b(3))) return
      ga = a + offset
      gb = b + offset
      outranks = .false.
      do d = 3, 1, -1
        if (ga(d) == gb(d)) cycle
        outranks = ga(d) > gb(d)
        return
      end do
    end function outranks
  end subroutine group_roots


  !> Small cells that no group holds mixed with their ring (manual/theory.md section 7b). A
  !> wet cell s is lonely when its group fraction (filled, what group_roots formed the groups
  !> by) is below small and its root's is too: alone, or in a group of small cells only (a
  !> sheet or a spray thinner than a cell, where no chain of joins reaches a cell that is not
  !> small). Its faces' fluxes would act on a fraction too small for the time step. It gives
  !> each wet ring neighbour t inside the domain, in the manner of Hu, Khoo, Adams and Huang's
  !> mixing (J. Comput. Phys. 219, 2006), the part a_t / sum(a) (t's share of the material
  !> volume of s's ring, a = alpha V) of what brings the pair to one state,
  !> (a_t C_s V_s - a_s C_t V_t) / (a_s + a_t), and t takes it; where t is lonely too the two
  !> exchanges are added. Each exchange is made from the content as it came (cq over the
  !> padded block, before the groups) and added to the contents c of the interior cells in
  !> box (after the groups), so that every block computes a pair alike: it reads s's ring and
  !> root, within two cells of the block's interior. count: the lonely cells of box. Each
  !> cell's loneliness is decided once, over box and one cell round it; a block with none
  !> there (most blocks, most stages) walks no ring.
  subroutine mix_lonely(lay, offset, e, alpha_e, filled, root, small, cq, box, c, count)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), e(3), box(2, 3)
    real(wp), intent(in) :: alpha_e(1-e(1):, 1-e(2):, 1-e(3):)
    real(wp), intent(in) :: filled(1-e(1):, 1-e(2):, 1-e(3):)   !< the groups' fractions
    integer, allocatable, intent(in) :: root(:, :, :, :)        !< group_roots'
    real(wp), intent(in) :: small
    real(wp), intent(in) :: cq(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(inout) :: c(:, :, :, :)   !< (interior cell, variable) contents
    integer, intent(inout) :: count
    !> (the ring's reach along each direction)
    integer, parameter :: w(3) = [1, 1, 1]
    logical :: lone(box(1, 1)-w(1):box(2, 1)+w(1), box(1, 2)-w(2):box(2, 2)+w(2), &
      box(1, 3)-w(3):box(2, 3)+w(3))
    integer :: i, j, k, l, nb(3, 26), nl, r(3)
    r = merge(w, 0, [1, 2, 3] <= lay%ndim)
    lone = .false.
    do k = box(1, 3) - r(3), box(2, 3) + r(3)
      do j = box(1, 2) - r(2), box(2, 2) + r(2)
        do i = box(1, 1) - r(1), box(2, 1) + r(1)
          lone(i, j, k) = lonely([i, j, k])
        end do
      end do
    end do
    if (.not. any(lone)) return
    do k = box(1, 3), box(2, 3)
      do j = box(1, 2), box(2, 2)
        do i = box(1, 1), box(2, 1)
          if (.not. alpha_e(i, j, k) > 0.0_wp) cycle
          if (.not. any(lone(i-r(1):i+r(1), j-r(2):j+r(2), k-r(3):k+r(3)))) cycle
          if (lone(i, j, k)) count = count + 1
          call ring(lay%ndim, [i, j, k], nb, nl)
          do l = 1, nl
            if (.not. alpha_e(nb(1, l), nb(2, l), nb(3, l)) > 0.0_wp) cycle
            if (.not. in_domain(lay, offset, nb(:, l))) cycle
            if (lone(i, j, k)) c(i, j, k, :) = c(i, j, k, :) &
              - given([i, j, k], nb(:, l)) / cell_volume(lay, offset, i)
            if (lone(nb(1, l), nb(2, l), nb(3, l))) c(i, j, k, :) = c(i, j, k, :) &
              + given(nb(:, l), [i, j, k]) / cell_volume(lay, offset, i)
          end do
        end do
      end do
    end do

  contains

    logical function lonely(c1)
      integer, intent(in) :: c1(3)
      integer :: r(3)
      lonely = .false.
      if (.not. (alpha_e(c1(1), c1(2), c1(3)) > 0.0_wp &
        .and. filled(c1(1), c1(2), c1(3)) < small)) return
      r = root(:, c1(1), c1(2), c1(3))
      lonely = filled(r(1), r(2), r(3)) < small
    end function lonely

    !> what lonely cell s gives its ring neighbour t (content times volume)
    function given(s, t) result(m)
      integer, intent(in) :: s(3), t(3)
      real(wp) :: m(size(cq, 4)), as, at, ring_a
      integer :: nb2(3, 26), n2, l2
      call ring(lay%ndim, s, nb2, n2)
      ring_a = 0.0_wp
      do l2 = 1, n2
        if (.not. in_domain(lay, offset, nb2(:, l2))) cycle
        ring_a = ring_a + alpha_e(nb2(1, l2), nb2(2, l2), nb2(3, l2)) &
          * cell_volume(lay, offset, nb2(1, l2))
      end do
      as = alpha_e(s(1), s(2), s(3)) * cell_volume(lay, offset, s(1))
      at = alpha_e(t(1), t(2), t(3)) * cell_volume(lay, offset, t(1))
      m = (at / ring_a) * (at * cq(s(1), s(2), s(3), :) * cell_volume(lay, offset, s(1)) &
        - as * cq(t(1), t(2), t(3), :) * cell_volume(lay, offset, t(1))) / (as + at)
    end function given
  end subroutine mix_lonely

  !> The neighbours of cell c within one cell in ndim directions: the 2 ndim face
  !> neighbours first (-x, +x, -y, +y, -z, +z), then the edge and corner ones (x fastest);
  !> nl of them (26 in 3D).
  pure subroutine ring(ndim, c, nb, nl)
    integer, intent(in) :: ndim, c(3)
    integer, intent(out) :: nb(3, 26), nl
    integer :: d, s, i, j, k, w(3)
    nl = 0
    do d = 1, ndim
      do s = -1, 1, 2
        nl = nl + 1
        nb(:, nl) = c
        nb(d, nl) = c(d) + s
      end do
    end do
    w = 0
    w(1:ndim) = 1
    do k = -w(3), w(3)
      do j = -w(2), w(2)
        do i = -w(1), w(1)
          if (abs(i) + abs(j) + abs(k) < 2) cycle
          nl = nl + 1
          nb(:, nl) = c + [i, j, k]
        end do
      end do
    end do
  end subroutine ring

  !> Whether cell c (block coordinates) is a first or last cell along an outflow side.
  pure logical function on_open(lay, offset, open_side, c) result(yes)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), c(3)
    logical, intent(in) :: open_side(2, 3)
    integer :: d
    yes = .false.
    do d = 1, lay%ndim
      if (offset(d) + c(d) == 1 .and. open_side(1, d)) yes = .true.
      if (offset(d) + c(d) == lay%cells(d) .and. open_side(2, d)) yes = .true.
    end do
  end function on_open

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
  !> fraction > 0, the first in -x, +x, -y, +y, -z, +z of equal ones (corners: the edge and
  !> corner neighbours instead, in the order of ring); huge(1) when none.
  pure function largest_neighbour(lay, offset, n, e, alpha_e, c, corners) result(best)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), n(3), e(3), c(3)
    real(wp), intent(in) :: alpha_e(1-e(1):, 1-e(2):, 1-e(3):)
    logical, intent(in), optional :: corners
    integer :: best(3), nb(3, 26), l, nl, first, last
    real(wp) :: a, top
    call ring(lay%ndim, c, nb, nl)
    first = 1
    last = 2 * lay%ndim
    if (present(corners)) then
      if (corners) then
        first = 2 * lay%ndim + 1
        last = nl
      end if
    end if
    best = huge(1)
    top = 0.0_wp
    do l = first, last
      if (any(nb(:, l) < 1 - e .or. nb(:, l) > n + e)) cycle
      if (.not. in_domain(lay, offset, nb(:, l))) cycle
      a = alpha_e(nb(1, l), nb(2, l), nb(3, l))
      if (a > top) then
        top = a
        best = nb(:, l)
      end if
    end do
  end function largest_neighbour

  !> The first pass of turning content into states, on block blk (number b) after the halo
  !> exchange, for the cells whose fraction has reached 0 or 1 since the last step's end
  !> (alpha_prev): their content is brought to what their fraction says, by exchange with
  !> their neighbours, so that the drift between the level set and the content (manual/
  !> theory.md section 7c) stays in the cut cells, where the content, not the fraction,
  !> decides how much material a cell holds:
  !> - a cell the surface has left (alpha = 0) gives what content it still holds to its face
  !>   neighbour of largest fraction;
  !> - a cell that has turned full (alpha = 1) gives the mass it holds beyond the density of
  !>   the full cells beside it, with its state per mass, to the cut cells around it (face,
  !>   edge and corner neighbours) by the material their fractions hold; or takes what it
  !>   lacks from them by the mass they hold (filled_excess).
  !> The interior's content afterwards goes into q (the caller exchanges it again before
  !> cut_open, unless no block's content changed: changed, bit for bit). Content with no wet
  !> neighbour stays (cut_open counts it as stranded). Beyond box (m_gfm_cut_box) every cell
  !> is dry and holds no content: none moves there.
  subroutine cut_donate(blk, ph, p, alpha_e, alpha_prev, box, changed, cbox)
    type(block_t), intent(inout) :: blk
    type(phases_t), intent(in) :: ph
    integer, intent(in) :: p
    real(wp), intent(in) :: alpha_e(:, :, :), alpha_prev(:, :, :)
    integer, intent(in) :: box(2, 3)
    logical, intent(out) :: changed
    integer, intent(out) :: cbox(2, 3)   !< the box of the cells that changed (empty: none)
    real(wp), allocatable :: given(:, :)   !< (variable, listed cell) its new content
    integer, allocatable :: at(:, :)       !< (3, listed cell) where it is
    logical, allocatable :: moving(:, :, :)   !< (over the box)
    !> (over the box and a cell around it) full now and at the last step's end
    logical, allocatable :: steady(:, :, :)
    integer :: e(3), n(3), i, j, k, lo, nf, l, m, w(3), bl(3), bh(3)
    lo = ph%lo(p)
    nf = ph%nflow
    associate (lay => blk%lay, q => blk%q)
      n = blk%n
      e = max(lay%ng - 1, 0)
      ! the cells whose content may change: nothing moves where the cell and its face
      ! neighbours were full and still are, nor out of an empty cell that holds nothing.
      ! Their new contents are made from q as it came, then put in (no copy of the block)
      w = merge(1, 0, [1, 2, 3] <= lay%ndim)
      ! (an empty box, of whatever corners, as 1..0)
      bl = box(1, :)
      bh = box(2, :)
      if (any(bl > bh)) then
        bl = 1
        bh = 0
      end if
      allocate(steady(bl(1)-w(1):bh(1)+w(1), bl(2)-w(2):bh(2)+w(2), bl(3)-w(3):bh(3)+w(3)))
      allocate(moving(bl(1):bh(1), bl(2):bh(2), bl(3):bh(3)))
      do k = bl(3) - w(3), bh(3) + w(3)
        do j = bl(2) - w(2), bh(2) + w(2)
          do i = bl(1) - w(1), bh(1) + w(1)
            steady(i, j, k) = alpha_e(i + e(1), j + e(2), k + e(3)) >= full .and. &
              alpha_prev(i + e(1), j + e(2), k + e(3)) >= full
          end do
        end do
      end do
      do k = bl(3), bh(3)
        do j = bl(2), bh(2)
          do i = bl(1), bh(1)
            moving(i, j, k) = .not. (steady(i, j, k) &
              .and. steady(i - w(1), j, k) .and. steady(i + w(1), j, k) &
              .and. steady(i, j - w(2), k) .and. steady(i, j + w(2), k) &
              .and. steady(i, j, k - w(3)) .and. steady(i, j, k + w(3)))
            if (moving(i, j, k)) then
              if (.not. alpha_e(i + e(1), j + e(2), k + e(3)) > 0.0_wp) &
                moving(i, j, k) = any(abs(q(i, j, k, lo:lo + nf - 1)) > 0.0_wp)
            end if
          end do
        end do
      end do
      allocate(given(nf, count(moving)), at(3, count(moving)))
      call exchange(q(:, :, :, lo:lo + nf - 1))
      ! (most moving cells give and take nothing: their content comes back as it was)
      changed = .false.
      cbox(1, :) = n + 1
      cbox(2, :) = 0
      do l = 1, size(at, 2)
        do m = 1, nf
          if (transfer(given(m, l), 1_i8) /= transfer(q(at(1, l), at(2, l), at(3, l), &
            lo + m - 1), 1_i8)) then
            changed = .true.
            cbox(1, :) = min(cbox(1, :), at(:, l))
            cbox(2, :) = max(cbox(2, :), at(:, l))
          end if
        end do
        q(at(1, l), at(2, l), at(3, l), lo:lo + nf - 1) = given(:, l)
      end do
    end associate

  contains

    !> The new contents of the moving cells into given (at: where), from the content cq.
    subroutine exchange(cq)
      real(wp), intent(in) :: cq(1-blk%lay%ng(1):, 1-blk%lay%ng(2):, 1-blk%lay%ng(3):, :)
      real(wp) :: u(ph%nflow), exj(ph%nflow, 26)
      integer :: ii, jj, kk, d, s, nb(3), best(3), m, nr, recv(3, 26), r, nbs(3, 26), nl, l
      !> the cells within one cell of the block that have turned full since the last step's
      !> end: the only ones that give to (or take from) the cut cells around them
      !> (over the box and a cell around it: the ring of a cell of the box)
      logical, allocatable :: filling(:, :, :)
      logical :: any_filling
      allocate(filling(bl(1)-w(1):bh(1)+w(1), bl(2)-w(2):bh(2)+w(2), bl(3)-w(3):bh(3)+w(3)))
      do kk = bl(3) - w(3), bh(3) + w(3)
        do jj = bl(2) - w(2), bh(2) + w(2)
          do ii = bl(1) - w(1), bh(1) + w(1)
            filling(ii, jj, kk) = alpha_at([ii, jj, kk]) >= full .and. &
              .not. alpha_prev(ii + e(1), jj + e(2), kk + e(3)) >= full
          end do
        end do
      end do
      any_filling = any(filling)
      m = 0
      do kk = bl(3), bh(3)
        do jj = bl(2), bh(2)
          do ii = bl(1), bh(1)
            if (.not. moving(ii, jj, kk)) cycle
            m = m + 1
            at(:, m) = [ii, jj, kk]
            u = cq(ii, jj, kk, :)
            if (.not. alpha_at([ii, jj, kk]) > 0.0_wp) then
              best = largest_neighbour(blk%lay, blk%offset, n, e, alpha_e, [ii, jj, kk])
              if (best(1) /= huge(1)) u = 0.0_wp
              given(:, m) = u
              cycle
            end if
            call filled_excess(cq, [ii, jj, kk], nr, recv, exj)
            do r = 1, nr
              u = u - exj(:, r)
            end do
            ! what the emptied face neighbours give this cell
            do d = 1, blk%lay%ndim
              do s = -1, 1, 2
                nb = [ii, jj, kk]
                nb(d) = nb(d) + s
                if (.not. in_domain(blk%lay, blk%offset, nb)) cycle
                if (alpha_at(nb) > 0.0_wp) cycle
                best = largest_neighbour(blk%lay, blk%offset, n, e, alpha_e, nb)
                if (all(best == [ii, jj, kk])) u = u + emptied_gift(cq, nb, [ii, jj, kk])
              end do
            end do
            ! what the filled neighbours give (or take from) this cell
            if (.not. any_filling) then
              given(:, m) = u
              cycle
            end if
            call ring(blk%lay%ndim, [ii, jj, kk], nbs, nl)
            do l = 1, nl
              nb = nbs(:, l)
              if (.not. filling(nb(1), nb(2), nb(3))) cycle
              if (.not. in_domain(blk%lay, blk%offset, nb)) cycle
              call filled_excess(cq, nb, nr, recv, exj)
              do r = 1, nr
                if (all(recv(:, r) == [ii, jj, kk])) u = u + exj(:, r) &
                  * (cell_volume(blk%lay, blk%offset, nb(1)) / cell_volume(blk%lay, blk%offset, ii))
              end do
            end do
            given(:, m) = u
          end do
        end do
      end do
    end subroutine exchange

    !> What the emptied cell d gives cell c (per c's volume: the volumes differ along r in
    !> axisymmetry): its content. Where the fluxes drew more than it held (its mass below
    !> zero), c gives that mass back at c's own eps_p and w_c per mass, not at d's: a debt
    !> of mass repaid at d's ratio could leave c with more mass than plastic strain to carry
    !> and negative eps_p (theory.md 7b). Mass, momentum and energy move as they are.
    function emptied_gift(cq, d, c) result(g)
      real(wp), intent(in) :: cq(1-blk%lay%ng(1):, 1-blk%lay%ng(2):, 1-blk%lay%ng(3):, :)
      integer, intent(in) :: d(3), c(3)
      real(wp) :: g(size(cq, 4))
      g = cq(d(1), d(2), d(3), :) * (cell_volume(blk%lay, blk%offset, d(1)) &
        / cell_volume(blk%lay, blk%offset, c(1)))
      if (size(g) < i_wcold) return
      if (.not. (g(i_rho) < 0.0_wp .and. cq(c(1), c(2), c(3), i_rho) > 0.0_wp)) return
      g(i_epsp:i_wcold) = g(i_rho) * cq(c(1), c(2), c(3), i_epsp:i_wcold) &
        / cq(c(1), c(2), c(3), i_rho)
    end function emptied_gift

    real(wp) function alpha_at(c)
      integer, intent(in) :: c(3)
      alpha_at = alpha_e(c(1) + e(1), c(2) + e(2), c(3) + e(3))
    end function alpha_at

    !> For a cell c that has turned full since the last step: the content it gives to each
    !> of its nr cut neighbours recv (exj, per c's volume; negative where it takes). It gives
    !> the mass it holds beyond the density of the full cells beside it to the cut cells
    !> around it (face, edge and corner neighbours with 0 < alpha < 1) in proportion to the
    !> material their fractions hold, alpha V, so that the drift is spread along the surface
    !> rather than handed on to one cell; a lack is taken from them in proportion to the
    !> mass they hold, at most half of each one's, at its own state per mass (so that eps_p
    !> and w_c stay within range). nr = 0 where c has not turned full or has no cut neighbour.
    subroutine filled_excess(cq, c, nr, recv, exj)
      real(wp), intent(in) :: cq(1-blk%lay%ng(1):, 1-blk%lay%ng(2):, 1-blk%lay%ng(3):, :)
      integer, intent(in) :: c(3)
      integer, intent(out) :: nr, recv(3, 26)
      real(wp), intent(out) :: exj(:, :)
      real(wp) :: rho, a, ex(size(exj, 1)), wt(26), vc, vj, lack
      integer :: l, nl, nbs(3, 26), m(3)
      nr = 0
      if (.not. alpha_at(c) >= full) return
      if (alpha_prev(c(1) + e(1), c(2) + e(2), c(3) + e(3)) >= full) return
      if (.not. cq(c(1), c(2), c(3), i_rho) > 0.0_wp) return
      call ring(blk%lay%ndim, c, nbs, nl)
      do l = 1, nl
        m = nbs(:, l)
        if (any(m < 1 - e .or. m > n + e)) cycle
        if (.not. in_domain(blk%lay, blk%offset, m)) cycle
        a = alpha_at(m)
        if (.not. (a > 0.0_wp .and. a < full)) cycle
        nr = nr + 1
        recv(:, nr) = m
        wt(nr) = a * cell_volume(blk%lay, blk%offset, m(1))
      end do
      if (nr == 0) return
      rho = full_density(blk%lay, blk%offset, e, alpha_e, cq(:, :, :, i_rho), c)
      if (.not. rho > 0.0_wp) then
        nr = 0
        return
      end if
      ex = cq(c(1), c(2), c(3), :) * (1.0_wp - rho / cq(c(1), c(2), c(3), i_rho))
      vc = cell_volume(blk%lay, blk%offset, c(1))
      if (ex(i_rho) >= 0.0_wp) then
        do l = 1, nr
          exj(:, l) = ex * (wt(l) / sum(wt(1:nr)))
        end do
        return
      end if
      ! a lack: taken by the mass each holds (per c's volume), at most half of it
      do l = 1, nr
        m = recv(:, l)
        vj = cell_volume(blk%lay, blk%offset, m(1))
        wt(l) = max(cq(m(1), m(2), m(3), i_rho), 0.0_wp) * vj
      end do
      if (.not. sum(wt(1:nr)) > 0.0_wp) then
        nr = 0
        return
      end if
      do l = 1, nr
        m = recv(:, l)
        exj(:, l) = 0.0_wp
        if (.not. wt(l) > 0.0_wp) cycle
        vj = cell_volume(blk%lay, blk%offset, m(1))
        lack = min(-ex(i_rho) * wt(l) / sum(wt(1:nr)), &
          0.5_wp * cq(m(1), m(2), m(3), i_rho) * vj / vc)
        exj(:, l) = -lack * cq(m(1), m(2), m(3), :) / cq(m(1), m(2), m(3), i_rho)
      end do
    end subroutine filled_excess
  end subroutine cut_donate
end module m_gfm_cut_cells
