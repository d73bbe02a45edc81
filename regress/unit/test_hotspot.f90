!> Unit test of the hot-spot count (m_hotspot's hot_count): regions of face-connected cells
!> among listed cells of a grid, by their 0-based global index i + n1 (j + n2 k).
program test_hotspot
  use m_kinds, only: i8
  use m_comm, only: comm_init
  use m_hotspot, only: hot_count
  use m_test_check, only: check_start, check, check_done, int_text
  implicit none
  integer, parameter :: g2(3) = [10, 8, 1], g3(3) = [5, 4, 6]
  integer(i8), allocatable :: c(:)
  call comm_init()
  call check_start('hotspot_unit')
  ! nothing listed: no region
  allocate(c(0))
  call expect('empty', c, g2, 0)
  ! one cell; two cells side by side along x, along y
  call expect('one cell', [at2(3, 3)], g2, 1)
  call expect('pair along x', [at2(3, 3), at2(4, 3)], g2, 1)
  call expect('pair along y', [at2(3, 3), at2(3, 4)], g2, 1)
  ! touching at a corner only: two regions (face connectivity)
  call expect('diagonal pair', [at2(3, 3), at2(4, 4)], g2, 2)
  ! the last cell of a row and the first of the next: consecutive indices, not neighbours
  call expect('row wrap', [at2(9, 2), at2(0, 3)], g2, 2)
  ! two 2 x 2 squares apart, and an L joining three cells
  call expect('two squares', [at2(1, 1), at2(2, 1), at2(1, 2), at2(2, 2), at2(6, 5), &
    at2(7, 5), at2(6, 6), at2(7, 6)], g2, 2)
  call expect('L shape', [at2(5, 0), at2(5, 1), at2(6, 1)], g2, 1)
  ! a ring of 8 cells around a hole: one region; the same listed in another order
  c = [at2(2, 2), at2(3, 2), at2(4, 2), at2(4, 3), at2(4, 4), at2(3, 4), at2(2, 4), at2(2, 3)]
  call expect('ring', c, g2, 1)
  call expect('ring, reversed', c(size(c):1:-1), g2, 1)
  ! a U whose arms join only at its base, listed arms first (union of two roots)
  call expect('U, arms first', [at2(1, 5), at2(1, 6), at2(5, 5), at2(5, 6), at2(1, 4), &
    at2(2, 4), at2(3, 4), at2(4, 4), at2(5, 4)], g2, 1)
  ! 3D: a column along z is one region; the top of one column and the bottom of the next
  ! plane's first cell are consecutive layers of different columns
  call expect('z column', [at3(2, 1, 0), at3(2, 1, 1), at3(2, 1, 2), at3(2, 1, 3)], g3, 1)
  call expect('plane wrap', [at3(4, 3, 0), at3(0, 0, 1)], g3, 2)
  call expect('3D corners', [at3(0, 0, 0), at3(1, 1, 1), at3(4, 3, 5)], g3, 3)
  call check_done()

contains

  integer(i8) function at2(i, j)
    integer, intent(in) :: i, j
    at2 = int(i, i8) + int(g2(1), i8) * int(j, i8)
  end function at2

  integer(i8) function at3(i, j, k)
    integer, intent(in) :: i, j, k
    at3 = int(i, i8) + int(g3(1), i8) * (int(j, i8) + int(g3(2), i8) * int(k, i8))
  end function at3

  subroutine expect(what, cells, grid, n)
    character(len=*), intent(in) :: what
    integer(i8), intent(in) :: cells(:)
    integer, intent(in) :: grid(3), n
    integer :: got
    got = hot_count(cells, grid)
    call check(what // ': ' // int_text(n) // ' regions, got ' // int_text(got), got == n)
  end subroutine expect
end program test_hotspot
