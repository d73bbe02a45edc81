!> Decomposition kinetics of an energetic material (manual/reaction.md, theory.md section 8):
!> Arrhenius rates k(T) = A exp(-T_a / T), T_a = E / R, and their integration over a time
!> step at a frozen temperature. One step (Henson, Asay, Smilowitz & Dickson 2001, HMX):
!> d lambda / dt = (1 - lambda) k(T), lambda the mass fraction burnt, heat Q per kilogram
!> burnt; over dt, exactly, lambda_new = 1 - (1 - lambda) exp(-k dt) (eq. 8.1-8.2). Three
!> steps (Tarver, Chidester & Nichols 1996, table 1, HMX): A -> B -> C -> D, each first order
!> here as in LANL's EOSlib (the paper's own orders were not found; manual/reaction.md),
!> heats Q1 < 0 (endothermic), Q2, Q3; at frozen T the chain is linear and is advanced by
!> the exponential of its rate matrix (eq. 8.3). The module owns the parameters (reaction_t)
!> and these pointwise formulas and row kernels; where the progress lives in the state and
!> when the source is applied is the solver's (m_gfm_stage). The deck's rules of a reaction
!> are here too (reaction_rules, handed m_deck_check's rule). No MPI, no I/O, no allocation.
module m_reaction
  use m_kinds, only: wp, name_len
  use m_text, only: choice_index
  use m_config, only: material_t, is_set
  use m_errors, only: rule_i
  implicit none
  private
  public :: reaction_rules
  public :: reaction_t, reaction_names, reaction_none, reaction_henson
  public :: reaction_from_name, arrhenius_rate, burn_step, reaction_row
  public :: tarver3_t, tarver3_hmx, tarver3_step
  public :: r_gas, henson_a, henson_t_act

  integer, parameter :: reaction_none = 0, reaction_henson = 1
  !> the deck's names (&material reaction): name k stands for model k - 1
  character(len=name_len), parameter :: reaction_names(2) = [character(len=name_len) :: &
    'none', 'henson']
  real(wp), parameter :: r_gas = 8.314462618_wp        !< J/(mol K)
  !> Henson et al. (LA-UR-01-3499): E = 149 kJ/mol, ln A = 29.35
  real(wp), parameter :: henson_t_act = 149.0e3_wp / r_gas   !< 17,920 K
  real(wp), parameter :: henson_a = 5.58e12_wp                !< 1/s
  real(wp), parameter :: cal = 4.184_wp                       !< J per thermochemical cal

  !> One-step kinetics of a material: model, prefactor A (1/s), activation temperature T_a
  !> (K), heat Q released per kilogram burnt (J/kg).
  type :: reaction_t
    integer :: model = reaction_none
    real(wp) :: a = 0.0_wp, t_act = 0.0_wp, q = 0.0_wp
  end type reaction_t

  !> A first-order chain of three steps: prefactors Z (1/s), activation temperatures (K),
  !> heats per kilogram converted by each step (J/kg, > 0 exothermic).
  type :: tarver3_t
    real(wp) :: z(3) = 0.0_wp, t_act(3) = 0.0_wp, q(3) = 0.0_wp
  end type tarver3_t

contains

  !> A material's reaction as the deck gives it (m_deck_check, handing its rule): none
  !> when left empty; a reaction needs its heat, and a heat a reaction.
  subroutine reaction_rules(m, in_m, rule)
    type(material_t), intent(inout) :: m
    character(len=*), intent(in) :: in_m
    procedure(rule_i) :: rule
    if (len_trim(m%reaction) == 0) m%reaction = 'none'
    call rule(m%reaction /= 'none' .and. .not. is_set(m%reaction_q), 'material reaction_q', &
      "missing required value (reaction '" // trim(m%reaction) // "' releases it)" // in_m)
    call rule(m%reaction == 'none' .and. is_set(m%reaction_q), 'material reaction', &
      "missing required value (reaction_q is given; HMX: 'henson')" // in_m)
  end subroutine reaction_rules

  !> The model of a deck name; 'none' (or empty) is no reaction.
  function reaction_from_name(name, q) result(rt)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: q     !< heat release (J/kg)
    type(reaction_t) :: rt
    if (len_trim(name) == 0) return
    rt%model = choice_index(reaction_names, name, 'reaction_from_name') - 1
    if (rt%model == reaction_henson) then
      rt%a = henson_a
      rt%t_act = henson_t_act
      rt%q = q
    end if
  end function reaction_from_name

  !> k(T) = A exp(-T_a / T) (eq. 8.1); 0 at T <= 0.
  elemental real(wp) function arrhenius_rate(a, t_act, t) result(k)
    real(wp), intent(in) :: a, t_act, t
    k = 0.0_wp
    if (t > 0.0_wp) k = a * exp(-t_act / t)
  end function arrhenius_rate

  !> lambda after dt at frozen T, exactly (eq. 8.2): 1 - (1 - lambda) exp(-k dt).
  elemental real(wp) function burn_step(rt, t, dt, lambda) result(lnew)
    type(reaction_t), intent(in) :: rt
    real(wp), intent(in) :: t, dt, lambda
    lnew = 1.0_wp - (1.0_wp - lambda) * exp(-arrhenius_rate(rt%a, rt%t_act, t) * dt)
    lnew = min(max(lnew, lambda), 1.0_wp)
  end function burn_step

  !> The reaction over dt on a row of n cells: rho lambda advanced at each cell's frozen
  !> temperature, and the heat rho Q d lambda added to rho E (total energy is not conserved:
  !> the chemical energy is released into it; eq. 8.4). Cells with mask false are skipped.
  pure subroutine reaction_row(rt, n, dt, temp, rho, rho_lambda, rho_en, mask)
    type(reaction_t), intent(in) :: rt
    integer, intent(in) :: n
    real(wp), intent(in) :: dt, temp(n), rho(n)
    real(wp), intent(inout) :: rho_lambda(n), rho_en(n)
    logical, intent(in) :: mask(n)
    integer :: i
    real(wp) :: lam, lnew
    do i = 1, n
      if (.not. mask(i)) cycle
      lam = min(max(rho_lambda(i) / rho(i), 0.0_wp), 1.0_wp)
      lnew = burn_step(rt, temp(i), dt, lam)
      rho_en(i) = rho_en(i) + rho(i) * rt%q * (lnew - lam)
      rho_lambda(i) = rho(i) * lnew
    end do
  end subroutine reaction_row

  !> Tarver, Chidester & Nichols (1996), table 1, HMX: ln Z = 48.7, 37.3, 28.1 (1/s);
  !> E = 52.7, 44.1, 34.1 kcal/mol; Q = -100, +300, +1200 cal/g (net 5.86 MJ/kg).
  pure function tarver3_hmx() result(tc)
    type(tarver3_t) :: tc
    tc%z = exp([48.7_wp, 37.3_wp, 28.1_wp])
    tc%t_act = [52.7_wp, 44.1_wp, 34.1_wp] * 1.0e3_wp * cal / r_gas
    tc%q = [-100.0_wp, 300.0_wp, 1200.0_wp] * cal * 1.0e3_wp
  end function tarver3_hmx

  !> The mass fractions y = (A, B, C, D) after dt at frozen T (first order each step), and
  !> the heat released per kilogram, heat = sum Q_s x_s with x_s the mass step s converted.
  !> y' = K y with K lower bidiagonal; y(dt) = exp(K dt) y(0), by scaling and squaring of a
  !> Taylor series (exact to round-off for any k dt, including equal rates, where the
  !> closed-form Bateman solution divides by k_i - k_j).
  pure subroutine tarver3_step(tc, t, dt, y, heat)
    type(tarver3_t), intent(in) :: tc
    real(wp), intent(in) :: t, dt
    real(wp), intent(inout) :: y(4)
    real(wp), intent(out) :: heat
    real(wp) :: k(3), m(4, 4), e(4, 4), term(4, 4), y0(4), x(3)
    integer :: s, i, j
    k = arrhenius_rate(tc%z, tc%t_act, t) * dt
    m = 0.0_wp
    do i = 1, 3
      m(i, i) = -k(i)
      m(i + 1, i) = k(i)
    end do
    ! scale so that the norm is below 1/2, then square back
    s = max(0, exponent(maxval(2.0_wp * k)) + 1)
    m = m / 2.0_wp**s
    e = 0.0_wp
    term = 0.0_wp
    do i = 1, 4
      e(i, i) = 1.0_wp
      term(i, i) = 1.0_wp
    end do
    do j = 1, 18
      term = matmul(term, m) / real(j, wp)
      e = e + term
    end do
    do i = 1, s
      e = matmul(e, e)
    end do
    y0 = y
    y = matmul(e, y0)
    y = max(y, 0.0_wp)
    ! what the three steps convert stays in the chain: D takes the rest (the squarings
    ! lose a few 1e-13 of the sum)
    y(4) = max(sum(y0) - sum(y(1:3)), 0.0_wp)
    x(1) = y0(1) - y(1)
    x(2) = (y0(1) + y0(2)) - (y(1) + y(2))
    x(3) = y(4) - y0(4)
    heat = sum(tc%q * x)
  end subroutine tarver3_step

end module m_reaction
