!> Wall-clock timers of the phases of a run and the memory the process holds, reported in
!> run.log. A timer_t holds one accumulator per named phase; no module-level state.
module m_timers
  use m_kinds, only: wp, name_len
  use m_comm, only: comm_wtime
  implicit none
  private
  public :: timers_t, timer_start, timer_stop, timer_total, memory_kb, node_memory_kb

  integer, parameter :: max_phases = 16

  type :: timers_t
    integer :: n = 0
    character(len=name_len) :: name(max_phases) = ''
    real(wp) :: total(max_phases) = 0.0_wp
    real(wp) :: started(max_phases) = 0.0_wp
  end type timers_t

contains

  integer function phase_index(t, name) result(k)
    type(timers_t), intent(inout) :: t
    character(len=*), intent(in) :: name
    do k = 1, t%n
      if (t%name(k) == name) return
    end do
    t%n = min(t%n + 1, max_phases)
    k = t%n
    t%name(k) = name
  end function phase_index

  subroutine timer_start(t, name)
    type(timers_t), intent(inout) :: t
    character(len=*), intent(in) :: name
    call timer_click(t, name, .true.)
  end subroutine timer_start

  subroutine timer_stop(t, name)
    type(timers_t), intent(inout) :: t
    character(len=*), intent(in) :: name
    call timer_click(t, name, .false.)
  end subroutine timer_stop

  !> Start phase `name`'s clock, or stop it and add the time since its start.
  subroutine timer_click(t, name, start)
    type(timers_t), intent(inout) :: t
    character(len=*), intent(in) :: name
    logical, intent(in) :: start
    integer :: k
    k = phase_index(t, name)
    if (start) then
      t%started(k) = comm_wtime()
    else
      t%total(k) = t%total(k) + (comm_wtime() - t%started(k))
    end if
  end subroutine timer_click

  real(wp) function timer_total(t, name)
    type(timers_t), intent(inout) :: t
    character(len=*), intent(in) :: name
    timer_total = t%total(phase_index(t, name))
  end function timer_total

  !> A memory figure of this process in kB from /proc/self/status ('VmHWM' = peak resident,
  !> 'VmRSS' = resident now); 0 where the file does not exist.
  real(wp) function memory_kb(key) result(kb)
    character(len=*), intent(in) :: key
    kb = proc_value_kb('/proc/self/status', key)
  end function memory_kb

  !> The memory of the node in kB from /proc/meminfo: 'MemAvailable' (what can be taken
  !> without swapping, with the page cache that can be dropped) or 'MemTotal'; 0 where the
  !> file does not exist.
  real(wp) function node_memory_kb(key) result(kb)
    character(len=*), intent(in) :: key
    kb = proc_value_kb('/proc/meminfo', key)
  end function node_memory_kb

  !> The number after 'key:' in a /proc file of 'key: value kB' lines.
  real(wp) function proc_value_kb(path, key) result(kb)
    character(len=*), intent(in) :: path, key
    character(len=256) :: line
    integer :: u, ios, k
    kb = 0.0_wp
    open(newunit=u, file=path, action='read', iostat=ios)
    if (ios /= 0) return
    do
      read(u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (index(line, key // ':') == 1) then
        k = index(line, ':')
        read(line(k + 1:), *, iostat=ios) kb
        exit
      end if
    end do
    close(u)
  end function proc_value_kb

end module m_timers
