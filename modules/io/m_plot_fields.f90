!> The plot fields (&output fields; DESIGN section 7, manual/user-guide.md): the names a deck may
!> ask for, the standard list when it asks for none, and the effects that some of them show.
!> m_output computes them; m_deck_check hands its rule to fields_resolve (m_errors' rule_i).
module m_plot_fields
  use m_kinds, only: name_len
  use m_errors, only: rule_i
  use m_text, only: in_list
  implicit none
  private
  public :: fields_resolve

  character(len=*), parameter :: field_names = 'rho, u, v, w, p, e, T, c, mach, phase, ' &
    // 'sxx, syy, szz, sxy, syz, sxz, eps_p, seq, lambda'
  character(len=*), parameter :: strength_fields = 'sxx, syy, szz, sxy, syz, sxz, eps_p, seq'
  !> the standard fields; T, eps_p and seq only where they apply (fields_resolve)
  character(len=5), parameter :: default_fields(9) = [character(len=5) :: 'rho', 'u', 'v', &
    'w', 'p', 'e', 'T', 'eps_p', 'seq']

contains

  !> fields(1:n): the fields given (blanks between them dropped), each known and listed once,
  !> or, none given, the standard ones: T where every gas in use has a cv (temperature), the
  !> plastic strain and von Mises stress with strength, lambda with reaction. A field of an
  !> effect that is off is refused.
  subroutine fields_resolve(fields, n, temperature, strength, reaction, rule)
    character(len=*), intent(inout) :: fields(:)
    integer, intent(out) :: n
    logical, intent(in) :: temperature, strength, reaction
    procedure(rule_i) :: rule
    character(len=name_len), allocatable :: kept(:)
    integer :: k
    kept = pack(fields, fields /= '')
    do k = 1, size(kept)
      call rule(.not. in_list(kept(k), field_names), 'output fields', "unknown field '" &
        // trim(kept(k)) // "' (allowed: " // field_names // ')')
      call rule(any(kept(1:k - 1) == kept(k)), 'output fields', "field '" // trim(kept(k)) &
        // "' is listed twice")
    end do
    if (size(kept) == 0) then
      kept = pack(default_fields, [(.true., k = 1, 6), temperature, strength, strength])
      if (reaction) kept = [character(len=name_len) :: kept, 'lambda']
    end if
    n = size(kept)
    fields = ''
    fields(1:n) = kept
    do k = 1, n
      call rule(.not. reaction .and. fields(k) == 'lambda', 'output fields', "field 'lambda' " &
        // 'needs reaction, which is off (no material in use has a reaction)')
      call rule(.not. strength .and. in_list(fields(k), strength_fields), 'output fields', &
        "field '" // trim(fields(k)) // "' needs strength, which is off (no material in use " &
        // 'has a strength_model, or &physics strength = .false.)')
    end do
  end subroutine fields_resolve

end module m_plot_fields
