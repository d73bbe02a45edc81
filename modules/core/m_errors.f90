!> Errors and the run log. Two ways to stop:
!>  - fatal(where, what): an error that one rank found; prints and aborts every rank.
!>  - stop_collective(msg, ok): called by every rank with its own verdict; when any rank
!>    has ok = .false., the lowest such rank prints its message and all ranks exit(1).
!>    A deck's value refused is told by error_line's `ERROR <deck> &group var: why`.
!> log_line writes to stdout on rank 0 and to the run log once it is open; log_flush pushes
!> both out.
module m_errors
  use m_kinds, only: line_len, path_len
  use m_comm, only: comm_abort, comm_exit, comm_is_root, comm_minloc_rank, comm_rank
  implicit none
  private
  public :: fatal, stop_collective, error_line, log_open, log_close, log_line, log_flush, rule_i

  !> A deck rule as the deck layer records it (m_deck_schema's rule): when prohibited holds,
  !> the variable var ('group name') is refused for the reason why. Modules that know what
  !> their own deck values may be (m_scene's body_check) are handed it.
  abstract interface
    subroutine rule_i(prohibited, var, why)
      logical, intent(in) :: prohibited
      character(len=*), intent(in) :: var, why
    end subroutine rule_i
  end interface

  integer :: log_unit = 0
  logical :: log_is_open = .false.   !< newunit numbers are negative: keep a flag

contains

  subroutine fatal(where, what)
    character(len=*), intent(in) :: where, what
    write(0, '(a)') 'ERROR [' // trim(where) // ']: ' // trim(what)
    if (log_is_open) then
      write(log_unit, '(a)') 'ERROR [' // trim(where) // ']: ' // trim(what)
      flush(log_unit)
    end if
    call comm_abort(1)
  end subroutine fatal

  subroutine stop_collective(msg, ok)
    character(len=*), intent(in) :: msg
    logical, intent(in) :: ok
    integer :: who
    who = comm_minloc_rank(.not. ok)
    if (who < 0) return
    if (comm_rank() == who) then
      write(0, '(a)') trim(msg)
      if (log_is_open) write(log_unit, '(a)') trim(msg)
    end if
    if (log_is_open) close(log_unit)
    call comm_exit(1)
  end subroutine stop_collective

  !> `ERROR <base> <where>: <why> (typical value <typical>)`, without `<where>` or the
  !> parenthesis when they are blank.
  function error_line(base, where, why, typical) result(line)
    character(len=*), intent(in) :: base, where, why, typical
    character(len=:), allocatable :: line
    line = 'ERROR ' // base
    if (len_trim(where) > 0) line = line // ' ' // trim(where)
    line = line // ': ' // why
    if (len_trim(typical) > 0) line = line // ' (typical value ' // trim(typical) // ')'
  end function error_line

  subroutine log_open(path)
    character(len=*), intent(in) :: path
    integer :: ios
    if (.not. comm_is_root()) return
    open(newunit=log_unit, file=trim(path), status='replace', action='write', iostat=ios)
    log_is_open = (ios == 0)
    if (ios /= 0) call fatal('log_open', 'cannot write ' // trim(path) // &
      ': check that out_dir is writable')
  end subroutine log_open

  subroutine log_close()
    if (log_is_open) close(log_unit)
    log_is_open = .false.
  end subroutine log_close

  subroutine log_line(text)
    character(len=*), intent(in) :: text
    if (.not. comm_is_root()) return
    write(6, '(a)') trim(text)
    if (log_is_open) write(log_unit, '(a)') trim(text)
  end subroutine log_line

  !> Push what log_line wrote to stdout and the run log out now (a progress line must show
  !> while the run goes on, also when stdout is a pipe).
  subroutine log_flush()
    if (.not. comm_is_root()) return
    flush(6)
    if (log_is_open) flush(log_unit)
  end subroutine log_flush

end module m_errors
