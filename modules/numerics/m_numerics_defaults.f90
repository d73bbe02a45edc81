!> The defaults of &numerics that depend on the scene (manual/accuracy.md, "Defaults"): the
!> choices that the accuracy study measures best at equal cost for the scene's kind, filled in
!> where the deck leaves a choice out (empty in m_config), once the effects are resolved.
!> - scheme: weno5 for every kind (the whole Pareto front of the smooth wave and the Taylor
!>   bar, and with hllc the least error at every budget of Sod and Toro 3);
!> - flux: hllc for gas dynamics (7-14 % less error than llf on the Sod and Toro fronts for
!>   up to 20 % more time); llf with strength, the only flux of the elastic-plastic equations;
!> - scalar_flux (with strength): upwind, eps_p and w_c carried by the mass flux with bounded
!>   face values (manual/theory.md 5.1b, 5.1e); llf smears them where the material stagnates
!>   (the Taylor bar's peak eps_p 1.71 against 2.9 at 0.15 mm).
!> It chooses; it does not check (m_deck_check) and does not compute.
module m_numerics_defaults
  use m_kinds, only: line_len
  use m_config, only: config_t
  implicit none
  private
  public :: numerics_defaults

contains

  !> Fill the unset scheme, flux and scalar_flux of cfg for its scene (cfg%strength resolved)
  !> and say in note what was chosen and why (for run.log).
  subroutine numerics_defaults(cfg, note)
    type(config_t), intent(inout) :: cfg
    character(len=line_len), intent(out) :: note
    character(len=:), allocatable :: kind, chosen
    if (cfg%strength) then
      kind = 'solids (strength on)'
    else
      kind = 'gas dynamics (no strength)'
    end if
    chosen = ''
    if (len_trim(cfg%scheme) == 0) then
      cfg%scheme = 'weno5'
      chosen = chosen // '; scheme weno5 (on every Pareto front of the accuracy study)'
    end if
    if (len_trim(cfg%flux) == 0) then
      if (cfg%strength) then
        cfg%flux = 'llf'
        chosen = chosen // '; flux llf (the flux of the elastic-plastic equations)'
      else
        cfg%flux = 'hllc'
        chosen = chosen // '; flux hllc (7-14 % less error than llf on Sod and Toro)'
      end if
    end if
    if (len_trim(cfg%scalar_flux) == 0) then
      cfg%scalar_flux = 'upwind'
      if (cfg%strength) chosen = chosen // '; scalar_flux upwind (bounded eps_p and w_c; ' &
        // 'llf smears them where material stagnates)'
    end if
    if (len(chosen) == 0) then
      note = 'every choice set by the deck'
    else
      note = 'defaults for ' // kind // chosen
    end if
  end subroutine numerics_defaults

end module m_numerics_defaults
