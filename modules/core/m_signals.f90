!> Stop requests from outside the run (manual/user-guide.md "Running on batch queues"): a
!> batch queue warns a job with a signal before its time limit (Slurm `--signal=B:USR1@120`,
!> then SIGTERM at the limit; PBS qdel/qrerun send SIGTERM). signals_catch installs a handler
!> for SIGUSR1, SIGUSR2 and SIGTERM through the C library's signal(); the handler only stores
!> the signal's number in a volatile integer, the one async-signal-safe thing Fortran can do.
!> The time loop reads it once per step with signal_caught (agreed over the ranks by the
!> caller), writes a checkpoint and exits with exit_stopped. The module neither communicates
!> nor writes anything.
module m_signals
  use, intrinsic :: iso_c_binding, only: c_int, c_funptr, c_funloc
  implicit none
  private
  public :: signals_catch, signal_caught, signal_name, exit_stopped

  !> Exit status of a run that stopped before its end with a checkpoint to continue from
  !> (wall_limit or a caught signal); 75 is EX_TEMPFAIL of sysexits.h, "try again later".
  integer, parameter :: exit_stopped = 75

  ! Linux signal numbers (x86, ARM, POWER, RISC-V; signal.h is out of Fortran's reach)
  integer(c_int), parameter :: sigusr1 = 10_c_int, sigusr2 = 12_c_int, sigterm = 15_c_int

  !> The last signal caught, 0 for none. Module state by necessity: a signal handler has no
  !> argument to carry it in; signals_catch clears it.
  integer(c_int), volatile :: caught = 0_c_int

  interface
    function c_signal(signum, handler) bind(C, name='signal') result(previous)
      import :: c_int, c_funptr
      integer(c_int), value :: signum
      type(c_funptr), value :: handler
      type(c_funptr) :: previous
    end function c_signal
  end interface

contains

  !> Install the handler for SIGUSR1, SIGUSR2 and SIGTERM and forget any earlier signal.
  !> Called after the MPI start-up, so that ours is the handler in force.
  subroutine signals_catch()
    type(c_funptr) :: previous
    caught = 0_c_int
    previous = c_signal(sigusr1, c_funloc(on_signal))
    previous = c_signal(sigusr2, c_funloc(on_signal))
    previous = c_signal(sigterm, c_funloc(on_signal))
  end subroutine signals_catch

  !> The number of the last signal caught on this rank, 0 for none.
  integer function signal_caught() result(signum)
    signum = int(caught)
  end function signal_caught

  !> SIGUSR1, SIGUSR2, SIGTERM or 'signal N'.
  function signal_name(signum) result(name)
    integer, intent(in) :: signum
    character(len=16) :: name
    select case (signum)
    case (sigusr1)
      name = 'SIGUSR1'
    case (sigusr2)
      name = 'SIGUSR2'
    case (sigterm)
      name = 'SIGTERM'
    case default
      write(name, '(a,i0)') 'signal ', signum
    end select
  end function signal_name

  !> The handler: store the number and return (nothing else is safe inside a handler).
  subroutine on_signal(signum) bind(C)
    integer(c_int), value :: signum
    caught = signum
  end subroutine on_signal

end module m_signals
