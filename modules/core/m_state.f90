!> Layout of the conserved state vector U (DESIGN section 1, manual/theory.md eq. 1 and 5.1).
!> A gas deck carries the five Euler variables; when some material has strength the six
!> components of rho S (deviatoric stress, symmetric: xx, yy, zz, xy, yz, xz), rho eps_p
!> (effective plastic strain) and rho w_c (the part 1 - beta of the plastic work that is
!> stored in the lattice rather than turned into heat, beta = Taylor-Quinney) follow, and only
!> then. When a material reacts (&physics reaction), rho lambda (lambda the mass fraction
!> burnt, m_reaction) is appended after these, as the phase's last variable (phases_t's
!> i_lambda); without reaction the layout is the one above.
module m_state
  implicit none
  private
  public :: i_rho, i_mx, i_my, i_mz, i_en, n_euler
  public :: i_sxx, i_syy, i_szz, i_sxy, i_syz, i_sxz, i_epsp, i_wcold, n_solid, stress_index

  integer, parameter :: i_rho = 1   !< rho
  integer, parameter :: i_mx = 2    !< rho u
  integer, parameter :: i_my = 3    !< rho v
  integer, parameter :: i_mz = 4    !< rho w
  integer, parameter :: i_en = 5    !< rho E, E = e + |u|^2 / 2
  integer, parameter :: n_euler = 5
  integer, parameter :: i_sxx = 6, i_syy = 7, i_szz = 8   !< rho S, diagonal
  integer, parameter :: i_sxy = 9, i_syz = 10, i_sxz = 11 !< rho S, off-diagonal
  integer, parameter :: i_epsp = 12                       !< rho eps_p
  integer, parameter :: i_wcold = 13  !< rho w_c: plastic work stored, not heat (1 - beta)
  integer, parameter :: n_solid = 13

contains

  !> State index of the stress component S_ab (a, b in 1..3).
  pure integer function stress_index(a, b) result(k)
    integer, intent(in) :: a, b
    integer, parameter :: map(3, 3) = reshape([i_sxx, i_sxy, i_sxz, i_sxy, i_syy, i_syz, &
      i_sxz, i_syz, i_szz], [3, 3])
    k = map(a, b)
  end function stress_index
end module m_state
