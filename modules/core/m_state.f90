!> Layout of the conserved state vector U (DESIGN section 1, manual/theory.md eq. 1).
!> A gas deck carries the five Euler variables; the strength and plastic-strain variables
!> of later issues are appended only when an effect needs them.
module m_state
  implicit none
  private
  public :: i_rho, i_mx, i_my, i_mz, i_en, n_euler

  integer, parameter :: i_rho = 1   !< rho
  integer, parameter :: i_mx = 2    !< rho u
  integer, parameter :: i_my = 3    !< rho v
  integer, parameter :: i_mz = 4    !< rho w
  integer, parameter :: i_en = 5    !< rho E, E = e + |u|^2 / 2
  integer, parameter :: n_euler = 5
end module m_state
