!> history.csv (DESIGN section 7): a header line, then one row per history step. Only rank 0
!> writes; the values are reduced by the caller. A restart appends to the file it continues,
!> dropping rows past the restart step so that the history reads as one run.
module m_history
  use m_kinds, only: wp, path_len
  use m_comm, only: comm_is_root
  use m_errors, only: fatal
  implicit none
  private
  public :: history_t, history_open, history_write, history_close

  type :: history_t
    integer :: unit = 0
    logical :: is_open = .false.
  end type history_t

contains

  subroutine history_open(h, path, columns, restart_step)
    type(history_t), intent(inout) :: h
    character(len=*), intent(in) :: path, columns(:)
    integer, intent(in) :: restart_step   !< < 0: a new run
    character(len=4096) :: line
    character(len=path_len) :: tmp
    integer :: ios, in, out, step, k
    logical :: exists
    if (.not. comm_is_root()) return
    inquire(file=trim(path), exist=exists)
    if (restart_step >= 0 .and. exists) then
      ! keep the rows up to the restart step
      tmp = trim(path) // '.tmp'
      open(newunit=in, file=trim(path), status='old', action='read')
      open(newunit=out, file=trim(tmp), status='replace', action='write')
      do
        read(in, '(a)', iostat=ios) line
        if (ios /= 0) exit
        read(line, *, iostat=k) step
        if (k == 0) then
          if (step > restart_step) exit
        end if
        write(out, '(a)') trim(line)
      end do
      close(in)
      close(out)
      call execute_command_line('mv -f "' // trim(tmp) // '" "' // trim(path) // '"')
      open(newunit=h%unit, file=trim(path), status='old', position='append', action='write', &
        iostat=ios)
    else
      open(newunit=h%unit, file=trim(path), status='replace', action='write', iostat=ios)
      if (ios == 0) then
        write(h%unit, '(a)', advance='no') trim(columns(1))
        do k = 2, size(columns)
          write(h%unit, '(a)', advance='no') ',' // trim(columns(k))
        end do
        write(h%unit, '(a)') ''
      end if
    end if
    if (ios /= 0) call fatal('history_open', 'cannot write ' // trim(path))
    h%is_open = .true.
  end subroutine history_open

  subroutine history_write(h, step, values)
    type(history_t), intent(inout) :: h
    integer, intent(in) :: step
    real(wp), intent(in) :: values(:)
    integer :: k
    if (.not. h%is_open) return
    write(h%unit, '(i0)', advance='no') step
    do k = 1, size(values)
      write(h%unit, '(",",es24.16e3)', advance='no') values(k)
    end do
    write(h%unit, '(a)') ''
    flush(h%unit)
  end subroutine history_write

  subroutine history_close(h)
    type(history_t), intent(inout) :: h
    if (h%is_open) close(h%unit)
    h%is_open = .false.
  end subroutine history_close

end module m_history
