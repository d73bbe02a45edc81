!> Scratch of the cut-cell update's per-stage passes (issue 15, m_gfm_cut and the modules it
!> calls): the arrays the geometry, the content-to-state pass and the closing cells fill for
!> one block at a time, kept from block to block and stage to stage, refitted only when a
!> block of another shape comes. Allocating them afresh at every stage (and the kernel
!> faulting in and zeroing their pages) was a good part of the update's cost
!> (manual/performance.md). Holds no state between the passes: every pass writes what it
!> reads.
module m_gfm_cut_work
  use m_kinds, only: wp
  implicit none
  private
  public :: cut_work_t, fit_work

  type :: cut_work_t
    real(wp), allocatable :: phi(:, :, :)         !< level set continued past open sides
    real(wp), allocatable :: ax(:, :, :), ay(:, :, :), az(:, :, :)   !< apertures
    real(wp), allocatable :: plane(:, :, :)       !< planar fractions
    real(wp), allocatable :: relaxed(:, :, :, :)  !< content after the closing cells' exchange
    real(wp), allocatable :: rho(:, :, :)         !< mass content over the padded block
    real(wp), allocatable :: filled(:, :, :)      !< the fractions the groups are formed by
    integer, allocatable :: root(:, :, :, :)      !< each cell's group root
    integer :: box(2, 3) = 0                      !< where the geometry's scratch is not zero
  end type cut_work_t

  !> a (re)allocated with the bounds given when it does not have them (contents undefined)
  interface fit_work
    module procedure fit_real3, fit_int4
  end interface fit_work

contains

  subroutine fit_real3(a, lo, hi)
    real(wp), allocatable, intent(inout) :: a(:, :, :)
    integer, intent(in) :: lo(3), hi(3)
    if (allocated(a)) then
      if (all(lbound(a) == lo) .and. all(ubound(a) == hi)) return
      deallocate(a)
    end if
    allocate(a(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)))
  end subroutine fit_real3

  subroutine fit_int4(a, lo, hi)
    integer, allocatable, intent(inout) :: a(:, :, :, :)
    integer, intent(in) :: lo(4), hi(4)
    if (allocated(a)) then
      if (all(lbound(a) == lo) .and. all(ubound(a) == hi)) return
      deallocate(a)
    end if
    allocate(a(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), lo(4):hi(4)))
  end subroutine fit_int4
end module m_gfm_cut_work
