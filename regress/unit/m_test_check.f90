!> The assertions of the Fortran unit tests (regress/unit/test_*.f90), compiled once by the
!> Makefile's bin/test_% rule. A test calls check_start, then any number of checks, then
!> check_done, which every rank must reach: it adds up the passed and failed checks over
!> the ranks (m_comm), prints one summary line on rank 0 (PASS name (N checks[, R ranks])
!> or FAIL name: F of N checks failed) and ends the run with exit status 0 or 1.
!> A failed check prints FAIL and its message (with the rank on more than one rank), the
!> first max_shown of each rank only; verbose tests print the passing ones as ok too.
!> A NaN never passes. int_text writes an integer for a message.
module m_test_check
  use m_kinds, only: wp, i8
  use m_text, only: int_text
  use m_comm, only: comm_rank, comm_size, comm_sum, comm_exit, comm_is_root
  implicit none
  private
  public :: check_start, check, check_error, check_close, check_failures, check_done
  public :: int_text

  integer, parameter :: max_shown = 20        !< failures printed per rank
  character(len=:), allocatable :: test_name
  logical :: verbose = .false.
  integer :: n_pass = 0, n_fail = 0

contains

  !> Start a test: its name for the summary; verbose prints every passing check as well.
  subroutine check_start(name, show_passes)
    character(len=*), intent(in) :: name
    logical, intent(in), optional :: show_passes
    test_name = name
    verbose = .false.
    if (present(show_passes)) verbose = show_passes
    n_pass = 0
    n_fail = 0
  end subroutine check_start

  !> A condition that must hold.
  subroutine check(what, ok)
    character(len=*), intent(in) :: what
    logical, intent(in) :: ok
    call record(ok, what)
  end subroutine check

  !> An error measure that must not exceed tol (err <= tol; NaN fails). shown, when given,
  !> is the value printed instead of err (e.g. a minimum whose negative is the error).
  subroutine check_error(what, err, tol, shown)
    character(len=*), intent(in) :: what
    real(wp), intent(in) :: err, tol
    real(wp), intent(in), optional :: shown
    character(len=40) :: text
    real(wp) :: value
    value = err
    if (present(shown)) value = shown
    write(text, '(a,es10.3,a,es8.1,a)') ': ', value, ' (tol ', tol, ')'
    call record(err <= tol, what // trim(text))
  end subroutine check_error

  !> got equal to expected within max(abs_tol, rel_tol |expected|) (rel_tol default 0).
  subroutine check_close(what, got, expected, abs_tol, rel_tol)
    character(len=*), intent(in) :: what
    real(wp), intent(in) :: got, expected, abs_tol
    real(wp), intent(in), optional :: rel_tol
    character(len=64) :: text
    real(wp) :: tol
    tol = abs_tol
    if (present(rel_tol)) tol = max(abs_tol, rel_tol * abs(expected))
    write(text, '(a,es23.15e3,a,es23.15e3)') ': got ', got, ', expected ', expected
    call record(abs(got - expected) <= tol, what // trim(text))
  end subroutine check_close

  !> The checks failed so far on this rank.
  integer function check_failures() result(n)
    n = n_fail
  end function check_failures

  !> Collective: the summary over all ranks on rank 0, then exit 0 (all passed) or 1.
  subroutine check_done()
    integer(i8) :: passed, failed
    character(len=32) :: ranks
    passed = comm_sum(int(n_pass, i8))
    failed = comm_sum(int(n_fail, i8))
    ranks = ''
    if (comm_size() > 1) write(ranks, '(a,i0,a)') ', ', comm_size(), ' ranks'
    if (comm_is_root()) then
      if (failed == 0 .and. passed > 0) then
        write(6, '(a,i0,a)') 'PASS ' // test_name // ' (', passed, ' checks' // trim(ranks) &
          // ')'
      else
        write(6, '(a,i0,a,i0,a)') 'FAIL ' // test_name // ': ', failed, ' of ', &
          passed + failed, ' checks failed' // trim(ranks)
      end if
    end if
    flush(6)
    if (failed == 0 .and. passed > 0) call comm_exit(0)
    call comm_exit(1)
  end subroutine check_done


  subroutine record(ok, text)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: text
    character(len=24) :: who
    who = ''
    if (comm_size() > 1) write(who, '(a,i0,a)') '[rank ', comm_rank(), ']'
    if (ok) then
      n_pass = n_pass + 1
      if (verbose) write(6, '(a)') '  ok   ' // trim(who) // ' ' // text
      return
    end if
    n_fail = n_fail + 1
    if (n_fail <= max_shown) write(6, '(a)') '  FAIL ' // trim(who) // ' ' // text
    if (n_fail == max_shown) write(6, '(a)') '  (further failures not shown) ' // trim(who)
  end subroutine record

end module m_test_check
