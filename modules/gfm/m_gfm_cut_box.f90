!> The boxes of the cut-cell update (issue 15, manual/performance.md): a box holds the
!> interior cells of a block that the phase's content can reach, (low, high) corner per
!> direction, empty when a low corner lies above its high one. Beyond it a cell's content is
!> zero (of either sign), its rate is +0 and its fraction 0: the stage's content there is +0
!> and its state the step start's, as the whole pass would make them, so the stage's passes
!> (stage_content, put_states, m_gfm_cut) compute only the box, where a body fills a few
!> blocks' corners. The states beyond it are assumed finite (0 times a state is a zero).
!> Boxes are m_gfm_cut's to keep; the kernels here take arrays and a box and nothing else.
module m_gfm_cut_box
  use m_kinds, only: wp
  implicit none
  private
  public :: box_union, box_nonzero, box_below, box_whole, box_empty, stage_content, put_states

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

  !> the smallest box of the cells where a < 0
  function box_below(a) result(box)
    real(wp), intent(in) :: a(:, :, :)
    integer :: box(2, 3)
    box = box_where(a, .true.)
  end function box_below

  !> the smallest box of the cells where a < 0 (below) or a is not zero (else); one pass
  !> along the rows
  function box_where(a, below) result(box)
    real(wp), intent(in) :: a(:, :, :)
    logical, intent(in) :: below
    integer :: box(2, 3), i, j, k
    logical :: hit(size(a, 1)), any_hit
    box(1, :) = shape(a) + 1
    box(2, :) = 0
    do k = 1, size(a, 3)
      do j = 1, size(a, 2)
        if (below) then
          hit = a(:, j, k) < 0.0_wp
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

  !> One variable's content c after a stage from the step start's c0 and the rate r (first:
  !> the first stage, c0 + dt r; else a c0 + (1 - a) (c + dt r)), and its copy u. Beyond the
  !> box (c0 and c zero, r +0) both are +0, which is what the sums give there.
  subroutine stage_content(first, a, dt, box, c0, r, c, u)
    logical, intent(in) :: first
    real(wp), intent(in) :: a, dt, c0(:, :, :), r(:, :, :)
    integer, intent(in) :: box(2, 3)
    real(wp), intent(inout) :: c(:, :, :)
    real(wp), intent(out) :: u(:, :, :)
    integer :: i, j, k, i0, i1
    do k = 1, size(c, 3)
      do j = 1, size(c, 2)
        call box_row(box, j, k, i0, i1)
        c(:i0 - 1, j, k) = 0.0_wp
        u(:i0 - 1, j, k) = 0.0_wp
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
        u(i1 + 1:, j, k) = 0.0_wp
      end do
    end do
  end subroutine stage_content

  !> One variable's states u of the full cells (kind 1: content c over fraction alpha) and
  !> of the cells without material (kind 0: the step start's, u0); the cut cells' (kind 2)
  !> are left. (Every cell of the box is written and no fraction but a full cell's divides,
  !> so that the loop runs without branches; beyond the box every cell is of kind 0.)
  subroutine put_states(box, kind, alpha, c, u0, u)
    integer, intent(in) :: box(2, 3), kind(:, :, :)
    real(wp), intent(in) :: alpha(:, :, :), c(:, :, :), u0(:, :, :)
    real(wp), intent(inout) :: u(:, :, :)
    integer :: i, j, k, i0, i1
    do k = 1, size(u, 3)
      do j = 1, size(u, 2)
        call box_row(box, j, k, i0, i1)
        u(:i0 - 1, j, k) = u0(:i0 - 1, j, k)
        do i = i0, i1
          u(i, j, k) = merge(c(i, j, k) / merge(alpha(i, j, k), 1.0_wp, kind(i, j, k) == 1), &
            merge(u0(i, j, k), u(i, j, k), kind(i, j, k) == 0), kind(i, j, k) == 1)
        end do
        u(i1 + 1:, j, k) = u0(i1 + 1:, j, k)
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
