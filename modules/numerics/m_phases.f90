!> The phases of a simulation (manual/interfaces.md section 1) and where they lie in a cell's
!> state vector: every phase carries its own flow state of nflow variables (n_euler, or
!> n_solid when some material has strength), one phase after another, then come the level
!> sets. Phase p's variables are q(:, :, :, ph%lo(p):ph%hi(p)), level set l is variable
!> ph%ils + l. Per phase: its material, equation of state, strength, shear modulus (0 without
!> strength) and rest state (density, pressure) of the cells it does not compute; its heat
!> conductivity (0: none) and reaction (m_reaction). With reaction on, every phase carries
!> rho lambda as its last flow variable (i_lambda = nflow), reacting or not, so that the
!> layout is one for all phases; without it i_lambda is 0 and nothing is appended.
module m_phases
  use m_kinds, only: wp, name_len
  use m_eos, only: eos_t
  use m_yield, only: strength_t
  use m_state, only: n_euler
  use m_reaction, only: reaction_t
  implicit none
  private
  public :: phases_t

  type :: phases_t
    integer :: nphase = 1              !< phases: the base material, then material bodies
    integer :: nflow = n_euler         !< flow variables of a phase: n_euler, or n_solid
    integer :: nvar = n_euler          !< flow variables of every phase, then the level sets
    integer :: ils = n_euler           !< level set l is variable ils + l
    character(len=name_len), allocatable :: material(:)
    type(eos_t), allocatable :: eos(:)
    type(strength_t), allocatable :: st(:)
    real(wp), allocatable :: shear(:)
    logical, allocatable :: strong(:)  !< the phase has strength
    real(wp), allocatable :: rest(:, :)  !< (rho, p) of its cells outside its region
    logical :: has_strength = .false.  !< the state carries rho S, rho eps_p and rho w_c
    character(len=256) :: strength_reason = ''
    real(wp), allocatable :: conductivity(:)   !< W/(m K); 0: the phase does not conduct
    type(reaction_t), allocatable :: rt(:)     !< the phase's kinetics (model none: inert)
    logical :: has_conduction = .false.        !< &physics heat_conduction
    logical :: has_reaction = .false.          !< &physics reaction: rho lambda in the state
    integer :: i_lambda = 0                    !< rho lambda in a phase's variables (0: none)
    character(len=256) :: conduction_reason = '', reaction_reason = ''
  contains
    procedure :: lo => phase_lo
    procedure :: hi => phase_hi
  end type phases_t

contains

  !> The first state variable of phase p.
  pure integer function phase_lo(ph, p) result(k)
    class(phases_t), intent(in) :: ph
    integer, intent(in) :: p
    k = (p - 1) * ph%nflow + 1
  end function phase_lo

  !> The last state variable of phase p.
  pure integer function phase_hi(ph, p) result(k)
    class(phases_t), intent(in) :: ph
    integer, intent(in) :: p
    k = p * ph%nflow
  end function phase_hi

end module m_phases
