!> Working precision and the integer kinds of the code.
!> Every real in SABRE is real(wp); the MPI datatype that matches wp lives in m_comm so that
!> physics modules never see MPI.
module m_kinds
  use, intrinsic :: iso_fortran_env, only: real64, int32, int64
  implicit none
  private
  public :: wp, i4, i8, name_len, path_len, line_len

  integer, parameter :: wp = real64
  integer, parameter :: i4 = int32
  integer, parameter :: i8 = int64
  integer, parameter :: name_len = 32    !< names of materials, bodies, schemes, bcs
  integer, parameter :: path_len = 256   !< file and folder paths
  integer, parameter :: line_len = 512   !< one line of a log or an error message
end module m_kinds
