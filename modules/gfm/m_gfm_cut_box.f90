!> The boxes of the cut-cell update (issue 15, manual/performance.md): a box holds the
!> interior cells of a block that the phase's content can reach, (low, high) corner per
!> direction, empty when a low corner lies above its high one. Beyond it a cell's content is
!> zero (of either sign), its rate is +0 and its fraction 0: the stage's content there is +0
!> and its state the step start's, as the whole pass would make them, so the stage's passes
!> (stage_content, put_states, m_gfm_cut) compute only the box, where a body fills a few
!> blocks' corners. The states beyond it are assumed finite (0 times a state is a zero).
!> Boxes are m_gfm_cut's to keep; the kernels here take arrays and a box and nothing else.
!> Of the dry cells beyond the box, the passes write the phase's variables in q only where
!> something may read them (near_cells: near the box); deep in a block's dry part q keeps
!> its state, which the ghost fill or the rest state makes again before anything reads it
!> (m_gfm_cut's cut_open).
module m_gfm_cut_box
  use m_kinds, only: wp
  implicit none
  private
  public :: box_union, box_nonzero, box_below, box_whole, box_empty, stage_content, put_states
  public :: near_cells, box_grown

  !> a box without a cell
  integer, parameter :: box_empty(2, 3) = reshape([1, 0, 1, 0, 1, 0], [2, 3])

contains

  !> the smallest box that holds boxes a and b
  pure function box_union(a, b) result(u)
    integer, intent(in) :: a(2, 3), b(2, 3)
    integer :: u(2, 3)
    if (any(a(1, :) > a(2, :))) then
      u = b
    else if (any(b(1, :) > b(2, :))) then
      u = a
    else
      u(1, :) = min(a(1, :), b(1, :))
      u(2, :) = max(a(2, :), b(2, :))
    end if
  end function box_union

  !> every cell of a block of n cells
  pure function box_whole(n) result(box)
    integer, intent(in) :: n(3)
    integer :: box(2, 3)
    box(1, :) = 1
    box(2, :) = n
  end function box_whole

  !> the smallest box of the cells where some variable of c is not zero (of either sign; a
  !> NaN is not zero)
  function box_nonzero(c) result(box)
    real(wp), intent(in) :: c(:, :, :, :)
    integer :: box(2, 3), m
    box = box_where(c(:, :, :, 1), .false.)
    do m = 2, size(c, 4)
      box = box_union(box, box_where(c(:, :, :, m), .false.))
    end do
  end function box_nonzero

  !> the smallest box of the cells where a < level (0 unless given)
  function box_below(a, level) result(box)
    real(wp), intent(in) :: a(:, :, :)
    real(wp), intent(in), optional :: level
    integer :: box(2, 3)
    box = box_where(a, .true., level)
  end function box_below

  !> the smallest box of the cells where a < level (below; level 0 unless given) or a is not
  !> zero (else); one pass along the rows
  function box_where(a, below, level) result(box)
    real(wp), intent(in) :: a(:, :, :)
    logical, intent(in) :: below
    real(wp), intent(in), optional :: level
    integer :: box(2, 3), i, j, k
    logical :: hit(size(a, 1)), any_hit
    real(wp) :: lv
    lv = 0.0_wp
    if (present(level)) lv = level
    box(1, :) = shape(a) + 1
    box(2, :) = 0
    do k = 1, size(a, 3)
      do j = 1, size(a, 2)
        if (below) then
          hit = a(:, j, k) < lv
        else
          hit = .not. abs(a(:, j, k)) <= 0.0_wp
        end if
        any_hit = .false.
        do i = 1, size(a, 1)
          any_hit = any_hit .or. hit(i)
        end do
        if (.not. any_hit) cycle
        box(1, 1) = min(box(1, 1), findloc(hit, .true., dim=1))
        box(2, 1) = max(box(2, 1), findloc(hit, .true., dim=1, back=.true.))
        box(:, 2) = [min(box(1, 2), j), max(box(2, 2), j)]
        box(:, 3) = [min(box(1, 3), k), max(box(2, 3), k)]
      end do
    end do
  end function box_where

  !> The cells of a block of n cells (near, over its interior) within reach cells of box: the dry cells
  !> beyond the box that the stage's passes keep up to date. (A cell of the halo is read as
  !> content only near a wet cell of the block that reads it, and the box of the block it
  !> belongs to holds every cell within a cell of one wet in its halo: m_gfm_cut_geometry.)
  pure subroutine near_cells(box, reach, n, near)
    integer, intent(in) :: box(2, 3), reach, n(3)
    logical, allocatable, intent(inout) :: near(:, :, :)   !< (sized to n when it is not)
    integer :: g(2, 3)
    if (allocated(near)) then
      if (any(shape(near) /= n)) deallocate(near)
    end if
    if (.not. allocated(near)) allocate(near(n(1), n(2), n(3)))
    near = .false.
    g = box_grown(box, reach, n)
    if (any(g(1, :) > g(2, :))) return
    near(g(1, 1):g(2, 1), g(1, 2):g(2, 2), g(1, 3):g(2, 3)) = .true.
  end subroutine near_cells

  !> box grown by reach cells along each direction, within a block of n cells (empty stays
  !> empty)
  pure function box_grown(box, reach, n) result(g)
    integer, intent(in) :: box(2, 3), reach, n(3)
    integer :: g(2, 3)
    g = box
    if (any(box(1, :) > box(2, :))) return
    g(1, :) = max(box(1, :) - reach, 1)
    g(2, :) = min(box(2, :) + reach, n)
  end function box_grown

  !> One variable's content c after a stage from the step start's c0 and the rate r (first:
  !> the first stage, c0 + dt r; else a c0 + (1 - a) (c + dt r)), and its copy u. Beyond the
  !> box (c0 and c zero, r +0) both are +0, which is what the sums give there: c everywhere,
  !> u where near (near_cells; elsewhere u keeps the stage's input state).
  subroutine stage_content(first, a, dt, box, near, c0, r, c, u)
    logical, intent(in) :: first
    real(wp), intent(in) :: a, dt, c0(:, :, :), r(:, :, :)
    integer, intent(in) :: box(2, 3)
    logical, intent(in) :: near(:, :, :)
    real(wp), intent(inout) :: c(:, :, :)
    real(wp), intent(inout) :: u(:, :, :)
    integer :: i, j, k, i0, i1
    do k = 1, size(c, 3)
      do j = 1, size(c, 2)
        call box_row(box, j, k, i0, i1)
        c(:i0 - 1, j, k) = 0.0_wp
        do i = 1, i0 - 1
          if (near(i, j, k)) u(i, j, k) = 0.0_wp
        end do
        if (first) then
          do i = i0, i1
            c(i, j, k) = c0(i, j, k) + dt * r(i, j, k)
            u(i, j, k) = c(i, j, k)
          end do
        else
          do i = i0, i1
            c(i, j, k) = a * c0(i, j, k) + (1.0_wp - a) * (c(i, j, k) + dt * r(i, j, k))
            u(i, j, k) = c(i, j, k)
          end do
        end if
        c(i1 + 1:, j, k) = 0.0_wp
        do i = i1 + 1, size(c, 1)
          if (near(i, j, k)) u(i, j, k) = 0.0_wp
        end do
      end do
    end do
  end subroutine stage_content

  !> One variable's states u of the full cells (kind 1: content c over fraction alpha) and
  !> of the cells without material (kind 0: the step start's, u0, beyond the box where near);
  !> the cut cells' (kind 2) are left. (Every cell of the box is written and no fraction but a
  !> full cell's divides, so that the loop runs without branches; beyond the box every cell is
  !> of kind 0.)
  subroutine put_states(box, near, kind, alpha, c, u0, u)
    integer, intent(in) :: box(2, 3), kind(:, :, :)
    logical, intent(in) :: near(:, :, :)
    real(wp), intent(in) :: alpha(:, :, :), c(:, :, :), u0(:, :, :)
    real(wp), intent(inout) :: u(:, :, :)
    integer :: i, j, k, i0, i1
    do k = 1, size(u, 3)
      do j = 1, size(u, 2)
        call box_row(box, j, k, i0, i1)
        do i = 1, i0 - 1
          if (near(i, j, k)) u(i, j, k) = u0(i, j, k)
        end do
        do i = i0, i1
          u(i, j, k) = merge(c(i, j, k) / merge(alpha(i, j, k), 1.0_wp, kind(i, j, k) == 1), &
            merge(u0(i, j, k), u(i, j, k), kind(i, j, k) == 0), kind(i, j, k) == 1)
        end do
        do i = i1 + 1, size(u, 1)
          if (near(i, j, k)) u(i, j, k) = u0(i, j, k)
        end do
      end do
    end do
  end subroutine put_states

  !> the cells i0..i1 of row (j, k) in the box (i0 = 1, i1 = 0 when none)
  pure subroutine box_row(box, j, k, i0, i1)
    integer, intent(in) :: box(2, 3), j, k
    integer, intent(out) :: i0, i1
    i0 = box(1, 1)
    i1 = box(2, 1)
    if (k < box(1, 3) .or. k > box(2, 3) .or. j < box(1, 2) .or. j > box(2, 2) &
      .or. i0 > i1) then
      i0 = 1
      i1 = 0
    end if
  end subroutine box_row

end module m_gfm_cut_box
