!> The boxes of the cut-cell update (issue 15, manual/performance.md): a box holds the
!> interior cells of a block that the phase's content can reach, (low, high) corner per
!> direction, empty when a low corner lies above its high one. Beyond it a cell's content is
!> zero (of either sign), its rate is +0 and its fraction 0: the stage's content there is +0
!> and its state the step start's, as the whole pass would make them, so the stage's passes
!> (stage_content, put_states, m_gfm_cut) compute only the box, where a body fills a few
!> blocks' corners. The states beyond it are assumed finite (0 times a state is a zero).
!> Boxes are m_gfm_cut's to keep; the kernels here take arrays and a box and nothing else.
!> Of the dry cells beyond the box, the passes write the phase's variables in q only where
!> something may read them (near the box: a box grown by a reach); deep in a block's dry
!> part q keeps its state, which the ghost fill or the rest state makes again before anything
!> reads it (m_gfm_cut's cut_open).
module m_gfm_cut_box
  use m_kinds, only: wp
  implicit none
  private
  public :: box_union, box_nonzero, box_below, box_whole, box_empty, stage_content, put_states
  public :: above_beyond, box_grown

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
  !> NaN is not zero). Row by row, each variable is searched only beyond the cells that the
  !> ones before it already put in the row's span.
  function box_nonzero(c) result(box)
    real(wp), intent(in) :: c(:, :, :, :)
    integer :: box(2, 3), i, j, k, m, i0, i1, nx
    nx = size(c, 1)
    box(1, :) = shape(c(:, :, :, 1)) + 1
    box(2, :) = 0
    do k = 1, size(c, 3)
      do j = 1, size(c, 2)
        i0 = nx + 1
        i1 = 0
        do m = 1, size(c, 4)
          do i = 1, i0 - 1
            if (.not. abs(c(i, j, k, m)) <= 0.0_wp) then
              i0 = i
              exit
            end if
          end do
          do i = nx, max(i1, i0 - 1) + 1, -1
            if (.not. abs(c(i, j, k, m)) <= 0.0_wp) then
              i1 = i
              exit
            end if
          end do
        end do
        if (i0 > i1) cycle
        box(1, 1) = min(box(1, 1), i0)
        box(2, 1) = max(box(2, 1), i1)
        box(:, 2) = [min(box(1, 2), j), max(box(2, 2), j)]
        box(:, 3) = [min(box(1, 3), k), max(box(2, 3), k)]
      end do
    end do
  end function box_nonzero

  !> the smallest box of the cells where a < level (0 unless given); along each row the
  !> first such cell from either end
  function box_below(a, level) result(box)
    real(wp), intent(in) :: a(:, :, :)
    real(wp), intent(in), optional :: level
    integer :: box(2, 3), i, j, k, i0, i1, nx
    real(wp) :: lv
    lv = 0.0_wp
    if (present(level)) lv = level
    nx = size(a, 1)
    box(1, :) = shape(a) + 1
    box(2, :) = 0
    do k = 1, size(a, 3)
      do j = 1, size(a, 2)
        i0 = nx + 1
        do i = 1, nx
          if (a(i, j, k) < lv) then
            i0 = i
            exit
          end if
        end do
        if (i0 > nx) cycle
        i1 = i0
        do i = nx, i0 + 1, -1
          if (a(i, j, k) < lv) then
            i1 = i
            exit
          end if
        end do
        box(1, 1) = min(box(1, 1), i0)
        box(2, 1) = max(box(2, 1), i1)
        box(:, 2) = [min(box(1, 2), j), max(box(2, 2), j)]
        box(:, 3) = [min(box(1, 3), k), max(box(2, 3), k)]
      end do
    end do
  end function box_below

  !> Whether every cell of a (a block's interior) beyond box is above level: the dry cells
  !> beyond the box that the stage's passes keep up to date (the box grown by a reach: near)
  !> may leave the others as they are only where the ghost fill's rest state replaces them
  !> (m_gfm_cut's cut_open). (A cell of the halo is read as content only near a wet cell of the
  !> block that reads it, and the box of the block it belongs to holds every cell within a
  !> cell of one wet in its halo: m_gfm_cut_geometry.)
  pure logical function above_beyond(box, a, level)
    integer, intent(in) :: box(2, 3)
    real(wp), intent(in) :: a(:, :, :), level
    integer :: j, k, i0, i1
    above_beyond = .false.
    do k = 1, size(a, 3)
      do j = 1, size(a, 2)
        call box_row(box, j, k, i0, i1)
        if (any(.not. a(:i0 - 1, j, k) > level)) return
        if (any(.not. a(i1 + 1:, j, k) > level)) return
      end do
    end do
    above_beyond = .true.
  end function above_beyond

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
  !> u in the box near (the box grown by a reach; elsewhere u keeps the stage's input state).
  subroutine stage_content(first, a, dt, box, near, c0, r, c, u)
    logical, intent(in) :: first
    real(wp), intent(in) :: a, dt, c0(:, :, :), r(:, :, :)
    integer, intent(in) :: box(2, 3), near(2, 3)
    real(wp), intent(inout) :: c(:, :, :)
    real(wp), intent(inout) :: u(:, :, :)
    integer :: i, j, k, i0, i1, n0, n1
    do k = 1, size(c, 3)
      do j = 1, size(c, 2)
        call box_row(box, j, k, i0, i1)
        call box_row(near, j, k, n0, n1)
        c(:i0 - 1, j, k) = 0.0_wp
        u(n0:min(n1, i0 - 1), j, k) = 0.0_wp
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
        u(max(n0, i1 + 1):n1, j, k) = 0.0_wp
      end do
    end do
  end subroutine stage_content

  !> One variable's states u of the full cells (kind 1: content c over fraction alpha) and
  !> of the cells without material (kind 0: the step start's, u0, beyond the box where in the
  !> box near); the cut cells' (kind 2) are left. (Every cell of the box is written and no
  !> fraction but a full cell's divides, so that the loop runs without branches; beyond the
  !> box every cell is of kind 0.)
  subroutine put_states(box, near, kind, alpha, c, u0, u)
    integer, intent(in) :: box(2, 3), near(2, 3), kind(:, :, :)
    real(wp), intent(in) :: alpha(:, :, :), c(:, :, :), u0(:, :, :)
    real(wp), intent(inout) :: u(:, :, :)
    integer :: i, j, k, i0, i1, n0, n1, rows(2, 3)
    rows = box_union(box, near)
    do k = rows(1, 3), rows(2, 3)
      do j = rows(1, 2), rows(2, 2)
        call box_row(box, j, k, i0, i1)
        call box_row(near, j, k, n0, n1)
        u(n0:min(n1, i0 - 1), j, k) = u0(n0:min(n1, i0 - 1), j, k)
        do i = i0, i1
          u(i, j, k) = merge(c(i, j, k) / merge(alpha(i, j, k), 1.0_wp, kind(i, j, k) == 1), &
            merge(u0(i, j, k), u(i, j, k), kind(i, j, k) == 0), kind(i, j, k) == 1)
        end do
        u(max(n0, i1 + 1):n1, j, k) = u0(max(n0, i1 + 1):n1, j, k)
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
