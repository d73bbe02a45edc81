!> What a deck may hold (DESIGN section 6): the one table of deck variables, a line each
!> (deck_table), through which the reader, the resolved-deck writer and the checks go; and
!> the errors, `ERROR <deck file> &<group> <variable>: <reason> (typical value <example>)`,
!> gathered in one pass so that a run reports them all: fail() records one (a variable gets
!> no second) and returns, deck_errors_stop() prints them and stops every rank (each rank
!> parses the same text and holds the same list), fail_now() when nothing more can be read.
module m_deck_schema
  use m_kinds, only: wp
  use m_config, only: config_t, material_t, body_t
  use m_errors, only: stop_collective, error_line
  use m_text, only: to_lower, joined
  use m_deck_parse, only: deck_var_t
  use m_boundary, only: bc_names
  use m_reconstruct, only: scheme_names
  use m_characteristic, only: variables_names
  use m_flux, only: flux_names, scalar_flux_names
  use m_gfm, only: probe_names
  use m_eos, only: eos_names
  use m_yield, only: strength_model_names
  use m_reaction, only: reaction_names
  implicit none
  private
  public :: deck_table, group_table, group_names, var_index
  public :: fail, fail_now, rule, deck_errors_begin, deck_errors_stop
  public :: deck_error_mark, deck_has_error

  character(len=8), parameter :: group_names(7) = [character(len=8) :: 'run', 'domain', &
    'numerics', 'physics', 'material', 'body', 'output']
  ! the choices that no module maps to constants (they are compared as names)
  character(len=12), parameter :: geometry_names(2) = [character(len=12) :: 'cartesian', &
    'axisymmetric']
  character(len=8), parameter :: surface_flux_names(2) = [character(len=8) :: 'material', 'llf']
  character(len=11), parameter :: conserve_names(5) = [character(len=11) :: 'auto', &
    'mass_energy', 'mass', 'none', 'cut_cell']
  character(len=14), parameter :: shape_names(7) = [character(len=14) :: 'box', 'sphere', &
    'cylinder', 'half_space', 'random_spheres', 'random_field', 'grains']
  character(len=9), parameter :: size_distribution_names(3) = [character(len=9) :: 'fixed', &
    'uniform', 'lognormal']

  !> the table being built: its lines so far and the group they belong to
  type :: table_t
    character(len=8) :: g = ''
    integer :: n = 0
    type(deck_var_t), allocatable :: v(:)   ! (grown by add: no limit on the lines)
  contains
    procedure :: add
  end type table_t

  ! what group_table binds to (its lines are read for their names, kinds and typical values)
  type(config_t), target, save :: proto
  ! the errors found so far (lines), and the variables they name ('&group var')
  character(len=:), allocatable :: err_base, err_text, err_keys
  integer, public, protected :: n_deck_errors = 0

contains

  !> THE TABLE: every deck variable, in the order of the resolved deck, bound to c (to m
  !> for &material, b for &body): name, component, typical value, meaning [, choices of a
  !> keyword; .true.: it may be left empty] [, allowed: the values it may take, as the error
  !> says them: `> a`, `>= a`, `< a`, `in (a, b]` with a bracket for a closed end, or
  !> `a, b or c`; a reason may follow]. A new variable is a component in m_config and a
  !> line here; a rule in m_deck_check only when it involves other variables.
  subroutine deck_table(c, m, b, vars)
    type(config_t), target, intent(inout) :: c
    type(material_t), target, intent(inout) :: m
    type(body_t), target, intent(inout) :: b
    type(deck_var_t), allocatable, intent(out) :: vars(:)
    type(table_t) :: t
    t%g = 'run'
    call t%add('title', c%title, "'sod shock tube'", 'title of the run (run.log)')
    call t%add('t_end', c%t_end, '0.2', 'end time (s); or give max_steps', allowed='> 0')
    call t%add('max_steps', c%max_steps, '10000', 'most time steps', allowed='>= 0')
    call t%add('wall_limit', c%wall_limit, '3600.0', 'wall-clock seconds, then checkpoint; 0 off', &
      allowed='>= 0 (0 = no limit)')
    call t%add('out_dir', c%out_dir, "'out/sod'", 'output folder')
    call t%add('overwrite', c%overwrite, '.true.', 'replace results already in out_dir')
    call t%add('restart', c%restart, "'out/sod/chk_000100.h5'", 'checkpoint to continue')
    call t%add('rebalance_threshold', c%rebalance_threshold, '1.1', 'migrate above it; 0 never')
    call t%add('rebalance_every', c%rebalance_every, '100', 'steps between balance checks; 0 none')
    call t%add('overlap', c%overlap, '.true.', 'compute blocks while halo messages travel')
    t%g = 'domain'
    call t%add('ndim', c%ndim, '2', 'number of dimensions, 1 to 3')
    call t%add('geometry', c%geometry, "'cartesian'", 'axisymmetric: x = r, y = z', geometry_names)
    call t%add('lo', c%lo, '0.0, 0.0, 0.0', 'low corner of the domain (m)')
    call t%add('hi', c%hi, '1.0, 0.5, 1.0', 'high corner of the domain (m)')
    call t%add('cells', c%cells, '200, 100, 1', 'cells along each direction')
    call t%add('block', c%block, '50, 50, 1', 'cells of a block along each direction (0 chosen)')
    call t%add('bc_lo', c%bc_lo, "'symmetry', 'outflow', 'outflow'", 'condition on the low sides', &
      bc_names)
    call t%add('bc_hi', c%bc_hi, "'outflow', 'outflow', 'outflow'", 'condition on the high sides', &
      bc_names)
    call t%add('bc_velocity', c%bc_velocity, '100.0, 0.0, 0.0', "normal velocity, 'velocity' sides")
    call t%add('bc_rise_time', c%bc_rise_time, '1.0e-6', 'linear ramp of bc_velocity from t = 0', &
      allowed='>= 0')
    call t%add('base_material', c%base_material, "'air'", "what fills the domain, or 'void'")
    t%g = 'numerics'
    call t%add('scheme', c%scheme, "'eno3'", 'reconstruction (empty: m_numerics_defaults)', &
      scheme_names, .true.)
    call t%add('variables', c%variables, "'characteristic'", 'reconstructed variables', &
      variables_names)
    call t%add('flux', c%flux, "'hllc'", 'flux of the Euler equations (empty: chosen)', &
      flux_names, .true.)
    call t%add('scalar_flux', c%scalar_flux, "'upwind'", 'solids: flux of rho eps_p, rho w_c', &
      scalar_flux_names, .true.)
    call t%add('surface_flux', c%surface_flux, "'material'", 'S, eps_p, w_c at a surface face', &
      surface_flux_names)
    call t%add('conserve', c%conserve, "'auto'", 'auto: cut_cell where it applies, else the ' &
      // 'fix mass_energy; or the fix returns mass_energy, mass, none', conserve_names)
    call t%add('rk_order', c%rk_order, '3', 'Runge-Kutta order, 1 to 3', allowed='1, 2 or 3')
    call t%add('cfl', c%cfl, '0.5', 'Courant number', allowed='in (0, 1]')
    call t%add('dt_max', c%dt_max, '1.0e-7', 'cap on dt (s), optional', &
      allowed='> 0 (leave it out for no cap)')
    call t%add('gfm_probe', c%gfm_probe, "'auto'", 'ghost-fluid probe', probe_names)
    call t%add('reinit_every', c%reinit_every, '5', 'steps between level-set reinitialisations', &
      allowed='>= 1 (steps between level-set reinitialisations)')
    call t%add('band', c%band, '6', 'ghost band (cells)', &
      allowed='>= 4 (the ghost band is 4 cells deep)')
    call t%add('contact_kappa', c%contact_kappa, '1.0', 'closer than 2 kappa dx is contact', &
      allowed='in (0, 3] (bodies closer than 2 kappa dx are in contact)')
    call t%add('body_follow', c%body_follow, '0.05', 'cut-cell update: a body''s level set ' &
      // 'follows its content beyond this drift (cells); 0: it does not; unset: 0.05 where ' &
      // 'bodies touch on cut cells, else 0', &
      allowed='in [0, 0.25] (cells; 0: no follow)')
    t%g = 'physics'
    call t%add('strength', c%strength, '.true.', 'strength (left out: when a material needs it)')
    call t%add('thermal', c%thermal, '.true.', 'plastic heating, softening (likewise)')
    call t%add('heat_conduction', c%heat_conduction, '.true.', 'conduction (left out: when a ' &
      // 'material has a conductivity)')
    call t%add('reaction', c%reaction, '.true.', 'reaction (left out: when a material reacts)')
    t%g = 'material'
    call t%add('name', m%name, "'water'", 'name; a library entry of that name is the start')
    call t%add('eos', m%eos, "'stiffened_gas'", 'equation of state', eos_names, .true.)
    call t%add('rho0', m%rho0, '1000.0', 'reference density (kg/m3)', allowed='> 0.0')
    call t%add('p0', m%p0, '1.0e5', 'reference (initial) pressure (Pa)')
    call t%add('gamma', m%gamma, '1.4', 'ratio of specific heats (gases)', allowed='> 1.0')
    call t%add('p_inf', m%p_inf, '6.0e8', 'stiffening pressure (Pa)', allowed='>= 0.0')
    call t%add('c0', m%c0, '3940.0', 'Mie-Gruneisen bulk sound speed (m/s)', allowed='> 0.0')
    call t%add('s', m%s, '1.49', 'Mie-Gruneisen Us-up slope', allowed='>= 0.0')
    call t%add('gruneisen', m%gruneisen, '2.0', 'Gruneisen Gamma0', allowed='>= 0.0')
    call t%add('cv', m%cv, '717.5', 'specific heat at constant volume (J/kg K)', allowed='> 0.0')
    call t%add('T0', m%T0, '293.15', 'reference temperature (K)', allowed='> 0.0')
    call t%add('bulk_modulus', m%bulk_modulus, '12.5e9', 'polynomial Mie-Gruneisen K (Pa)', &
      allowed='> 0.0')
    call t%add('poly_a', m%poly_a, '22.0e9', 'polynomial Mie-Gruneisen A (Pa)')
    call t%add('poly_b', m%poly_b, '15.0e9', 'polynomial Mie-Gruneisen B (Pa)')
    call t%add('strength_model', m%strength_model, "'johnson_cook'", 'strength (empty: none)', &
      strength_model_names, .true.)
    call t%add('shear_modulus', m%shear_modulus, '43.33e9', 'shear modulus G (Pa)', allowed='> 0.0')
    call t%add('yield0', m%yield0, '0.4e9', 'initial yield stress; Johnson-Cook A (Pa)', &
      allowed='>= 0.0')
    call t%add('hardening_modulus', m%hardening_modulus, '0.1e9', 'H = d sigma_y / d eps_p (Pa)', &
      allowed='>= 0.0')
    call t%add('jc_b', m%jc_b, '0.177e9', 'Johnson-Cook B (Pa)', allowed='>= 0.0')
    call t%add('jc_n', m%jc_n, '1.0', 'Johnson-Cook n', allowed='> 0.0')
    call t%add('jc_c', m%jc_c, '0.025', 'Johnson-Cook C', allowed='>= 0.0')
    call t%add('jc_m', m%jc_m, '1.09', 'Johnson-Cook m', allowed='> 0.0')
    call t%add('t_melt', m%t_melt, '1358.0', 'melt temperature (K): no strength above', &
      allowed='> 0.0')
    call t%add('melt_slope', m%melt_slope, '1.53', 'Kraut-Kennedy slope a: melt at t_melt (1 + ' &
      // 'a (1 - rho0 / rho))', allowed='>= 0.0')
    call t%add('eps_rate0', m%eps_rate0, '1.0', 'reference plastic strain rate (1/s)', &
      allowed='> 0.0')
    call t%add('vp_chi', m%vp_chi, '1.08', 'power law rate = chi eps_rate^m sigma^n (MPa^-n)', &
      allowed='> 0.0')
    call t%add('vp_m', m%vp_m, '-0.79', 'power law m', allowed='< 1.0')
    call t%add('vp_n', m%vp_n, '1.58', 'power law n', allowed='> 0.0')
    call t%add('taylor_quinney', m%taylor_quinney, '0.9', 'share of plastic work that heats', &
      allowed='in [0, 1] (the share of plastic work that heats)')
    call t%add('conductivity', m%conductivity, '0.4', 'heat conductivity k (W/(m K))', &
      allowed='> 0.0')
    call t%add('reaction', m%reaction, "'henson'", 'decomposition kinetics (empty: none)', &
      reaction_names, .true.)
    call t%add('reaction_q', m%reaction_q, '5.5e6', 'heat released per kg burnt (J/kg)', &
      allowed='> 0.0')
    t%g = 'body'
    call t%add('name', b%name, "'projectile'", 'name (empty: body<k>)')
    call t%add('material', b%material, "'copper'", "a material, 'void' or 'rigid'")
    call t%add('shape', b%shape, "'sphere'", 'shape', shape_names, .true.)
    call t%add('center', b%center, '0.5, 0.5, 0.0', 'centre; a point of a half_space (m)')
    call t%add('radius', b%radius, '0.1', 'radius of a sphere, cylinder; random_spheres (m)')
    call t%add('length', b%length, '0.2', 'length of a cylinder (m)')
    call t%add('axis', b%axis, '0.0, 0.0, 1.0', 'cylinder axis; outward normal of a half_space')
    call t%add('lo', b%lo, '0.0, 0.0, 0.0', 'low corner of a box, a random_* or grains (m)')
    call t%add('hi', b%hi, '0.5, 1.0, 1.0', 'high corner of a box, a random_* or grains (m)')
    call t%add('velocity', b%velocity, '1000.0, 0.0, 0.0', 'initial velocity (m/s)')
    call t%add('rho', b%rho, '1000.0', "initial density (unset: the material's rho0)")
    call t%add('p', b%p, '1.0e5', "initial pressure (unset: the material's p0)")
    call t%add('T', b%T, '300.0', 'initial temperature instead of p (K)')
    call t%add('amplitude', b%amplitude, '0.2', 'rho (or T if given) (1 + a sin(2 pi k.x))', &
      allowed='in (-1, 1) so that rho (1 + amplitude sin(2 pi k.x)) stays > 0')
    call t%add('wavevector', b%wavevector, '1.0, 0.0, 0.0', 'k of that perturbation (1/m)')
    ! the scene generators (manual/scenes.md): shapes random_spheres, random_field, grains
    call t%add('seed', b%seed, '1', 'random_*, grains: seed of the random numbers (any integer)')
    call t%add('volume_fraction', b%volume_fraction, '0.2', &
      'random_*, grains: share of the box lo..hi it fills (area in 2D)', allowed='in [0, 1)')
    call t%add('count', b%count, '100', 'random_spheres (0: from volume_fraction), grains: ' &
      // 'how many', allowed='>= 0')
    call t%add('colours', b%colours, '0', 'grains: most level sets; 0: as many as keep ' &
      // 'grains of one a ghost band apart (fewer: near grains share one)', allowed='>= 0')
    call t%add('size_distribution', b%size_distribution, "'fixed'", &
      'random_spheres: radius; uniform in radius_min..max; lognormal', size_distribution_names)
    call t%add('radius_min', b%radius_min, '4.0e-6', 'random_spheres: smallest radius (m)', &
      allowed='>= 0')
    call t%add('radius_max', b%radius_max, '6.0e-6', 'random_spheres: largest radius (m)', &
      allowed='>= 0')
    call t%add('radius_sigma', b%radius_sigma, '0.2', 'random_spheres lognormal: sd of ln r', &
      allowed='>= 0')
    call t%add('gap', b%gap, '1.0e-6', 'random_spheres: least gap, to each other and the box (m)', &
      allowed='>= 0')
    call t%add('correlation_length', b%correlation_length, '5.0e-6', &
      'random_field: l of its covariance exp(-r^2 / (2 l^2)) (m)', allowed='>= 0')
    t%g = 'output'
    call t%add('plot_dt', c%plot_dt, '1.0e-3', 'time between plots (s); 0: the final one', &
      allowed='>= 0 (0 = no plots by time)')
    call t%add('plot_every', c%plot_every, '100', 'steps between plots; 0 off', &
      allowed='>= 0 (0 = no plots by step)')
    call t%add('checkpoint_every', c%checkpoint_every, '1000', 'steps; 0: at wall_limit only', &
      allowed='>= 0 (0 = only at wall_limit)')
    call t%add('history_every', c%history_every, '10', 'steps between history.csv lines', &
      allowed='>= 1')
    call t%add('hot_thresholds', c%hot_thresholds, '700.0, 1000.0', &
      'hot-spot temperatures (K), up to 4; 0 unused (m_hotspot)')
    call t%add('fields', c%fields, "'rho', 'u', 'p'", 'plot fields (empty: a standard list)')
    t%v(t%n)%count => c%n_fields
    allocate(vars, source=t%v(1:t%n))
  end subroutine deck_table

  !> The lines of group gname (every line for ''), bound to a configuration kept for it.
  function group_table(gname) result(vars)
    character(len=*), intent(in) :: gname
    type(deck_var_t), allocatable :: vars(:)
    call deck_table(proto, proto%materials(1), proto%bodies(1), vars)
    if (len(gname) > 0) vars = pack(vars, vars%group == gname)
  end function group_table

  integer function var_index(vars, name) result(k)
    type(deck_var_t), intent(in) :: vars(:)
    character(len=*), intent(in) :: name
    k = findloc(to_lower(vars%name), name, 1)
  end function var_index

  !> A table line binding name to the component x (a scalar or an array of real, integer,
  !> logical or string); with choices a keyword (lower-cased, one of them; empty too when
  !> empty_ok); allowed: the values it may take (deck_table).
  subroutine add(t, name, x, typical, meaning, choices, empty_ok, allowed)
    class(table_t), intent(inout) :: t
    character(len=*), intent(in) :: name, typical, meaning
    class(*), target, intent(inout) :: x(..)
    character(len=*), intent(in), optional :: choices(:), allowed
    logical, intent(in), optional :: empty_ok
    type(deck_var_t) :: v
    v = deck_var_t(group=t%g, name=name, typical=typical, meaning=meaning)
    select rank (x)
    rank (0)
      select type (x)
      type is (real(wp))
        v%r => x
      type is (integer)
        v%i => x
      type is (logical)
        v%l => x
      type is (character(*))
        v%c => x
      end select
    rank (1)
      v%size = size(x)
      select type (x)
      type is (real(wp))
        v%ra => x
      type is (integer)
        v%ia => x
      type is (character(*))
        v%ca => x
      end select
    end select
    if (associated(v%i) .or. associated(v%ia)) v%kind = 'i'
    if (associated(v%l)) v%kind = 'l'
    if (associated(v%c)) v%clen = len(v%c)
    if (associated(v%ca)) v%clen = len(v%ca)
    if (v%clen > 0) v%kind = merge('k', 'c', present(choices))
    if (present(choices)) v%choices = joined(choices)
    if (present(empty_ok)) v%empty_ok = empty_ok
    if (present(allowed)) v%allowed = allowed
    if (.not. allocated(t%v)) allocate(t%v(64))
    if (t%n == size(t%v)) t%v = [t%v, t%v]
    t%n = t%n + 1
    t%v(t%n) = v
  end subroutine add

  !> Start reading the deck called base (the name in every error line) with no errors.
  subroutine deck_errors_begin(base)
    character(len=*), intent(in) :: base
    err_base = base
    err_text = ''
    err_keys = '|'
    n_deck_errors = 0
  end subroutine deck_errors_begin

  !> Record `ERROR <base> <where>: <why> (typical value <typical>)` and return, unless the
  !> variable of `where` has had an error already.
  subroutine fail(where, why, typical)
    character(len=*), intent(in) :: where, why, typical
    if (deck_has_error(where)) return
    call deck_error_mark(where)
    if (n_deck_errors > 0) err_text = err_text // new_line('a')
    err_text = err_text // error_line(err_base, where, why, typical)
    n_deck_errors = n_deck_errors + 1
  end subroutine fail

  !> fail(), then stop every rank with every error found so far.
  subroutine fail_now(where, why, typical)
    character(len=*), intent(in) :: where, why, typical
    call fail(where, why, typical)
    call deck_errors_stop()
  end subroutine fail_now

  !> Collective: when errors were found, print them, one a line, and stop every rank.
  subroutine deck_errors_stop()
    if (allocated(err_text)) call stop_collective(err_text, n_deck_errors == 0)
  end subroutine deck_errors_stop

  !> '&group var' of where (an index dropped), or '' outside a group.
  function error_key(where) result(key)
    character(len=*), intent(in) :: where
    character(len=:), allocatable :: key
    key = to_lower(trim(adjustl(where)))
    if (index(key, '(') > 0) key = key(1:index(key, '(') - 1)
  end function error_key

  !> Take the variable of where ('&group var') as wrong: it gets no error of its own later.
  !> '&group *' takes every variable of the group (a group missing or misspelled).
  subroutine deck_error_mark(where)
    character(len=*), intent(in) :: where
    if (index(error_key(where), ' ') == 0) return
    if (.not. deck_has_error(where)) err_keys = err_keys // error_key(where) // '|'
  end subroutine deck_error_mark

  !> Whether the variable of where ('&group var') has had an error, or its whole group.
  logical function deck_has_error(where) result(has)
    character(len=*), intent(in) :: where
    character(len=:), allocatable :: key
    key = error_key(where)   ! (without a blank: no variable, '|*|' is never there)
    has = index(err_keys, '|' // key // '|') > 0 .or. &
      index(err_keys, '|' // key(1:index(key, ' ')) // '*|') > 0
  end function deck_has_error

  !> One rule of the deck: when `prohibited` holds, the variable var ('group name', with an
  !> index maybe) is refused for the reason why, with its typical value from the table.
  subroutine rule(prohibited, var, why)
    logical, intent(in) :: prohibited
    character(len=*), intent(in) :: var, why
    type(deck_var_t), allocatable :: vars(:)
    integer :: blank, k
    if (.not. prohibited) return
    blank = index(var // ' ', ' ')
    vars = [group_table(var(1:blank - 1)), deck_var_t()]   ! (the last for no name or another)
    k = var_index(vars, to_lower(var(blank + 1:index(var // '(', '(') - 1)))
    call fail('&' // var, why, vars(merge(k, size(vars), k > 0))%typical)
  end subroutine rule

end module m_deck_schema
