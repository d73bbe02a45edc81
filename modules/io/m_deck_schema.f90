!> What a deck may hold (DESIGN section 6): its groups, and the variables of each with
!> kind, size and a typical value; and the one-line error that names them,
!>   ERROR <deck file> &<group> <variable>: <reason> (typical value <example>).
!> A deck's errors are gathered in one pass: fail() records a line and returns, so that
!> the reader and the checks go on and find the other mistakes; deck_errors_stop() then
!> prints every line and stops every rank (every rank parses the same text, so every rank
!> holds the same lines). A variable that has had an error gets no second one (a bad value
!> left at its default would otherwise also be "missing"). fail_now() is for an error after
!> which nothing more can be read (a syntax error). The list is module state, emptied by
!> deck_errors_begin() at the start of every deck read. It neither reads values (m_deck) nor
!> judges what they mean (m_deck_check).
module m_deck_schema
  use m_kinds, only: name_len, path_len
  use m_config, only: max_fields
  use m_errors, only: stop_collective
  use m_deck_text, only: to_lower
  use m_deck_values, only: var_info_t
  implicit none
  private
  public :: known_groups, run_vars, domain_vars, numerics_vars, physics_vars, material_vars, &
    body_vars, output_vars
  public :: fail, error_line, bad, group_vars, group_var, group_of, var_index
  public :: fail_now, deck_errors_begin, deck_errors_stop, deck_error_count, deck_error_mark, &
    deck_has_error

  character(len=*), parameter :: known_groups = &
    'run, domain, numerics, physics, material, body, output'
  type(var_info_t), parameter :: run_vars(7) = [ &
    var_info_t('title', 'c', 1, 128, "'sod shock tube'"), &
    var_info_t('t_end', 'r', 1, 0, '0.2'), &
    var_info_t('max_steps', 'i', 1, 0, '10000'), &
    var_info_t('wall_limit', 'r', 1, 0, '3600.0'), &
    var_info_t('out_dir', 'c', 1, path_len, "'out/sod'"), &
    var_info_t('overwrite', 'l', 1, 0, '.true.'), &
    var_info_t('restart', 'c', 1, path_len, "'out/sod/chk_000100.h5'")]
  type(var_info_t), parameter :: domain_vars(11) = [ &
    var_info_t('ndim', 'i', 1, 0, '2'), &
    var_info_t('geometry', 'c', 1, name_len, "'cartesian'"), &
    var_info_t('lo', 'r', 3, 0, '0.0, 0.0, 0.0'), &
    var_info_t('hi', 'r', 3, 0, '1.0, 0.5, 1.0'), &
    var_info_t('cells', 'i', 3, 0, '200, 100, 1'), &
    var_info_t('block', 'i', 3, 0, '50, 50, 1'), &
    var_info_t('bc_lo', 'c', 3, name_len, "'symmetry', 'outflow', 'outflow'"), &
    var_info_t('bc_hi', 'c', 3, name_len, "'outflow', 'outflow', 'outflow'"), &
    var_info_t('bc_velocity', 'r', 3, 0, '100.0, 0.0, 0.0'), &
    var_info_t('bc_rise_time', 'r', 1, 0, '1.0e-6'), &
    var_info_t('base_material', 'c', 1, name_len, "'air'")]
  type(var_info_t), parameter :: numerics_vars(12) = [ &
    var_info_t('scheme', 'c', 1, name_len, "'eno3'"), &
    var_info_t('flux', 'c', 1, name_len, "'hllc'"), &
    var_info_t('scalar_flux', 'c', 1, name_len, "'upwind'"), &
    var_info_t('surface_flux', 'c', 1, name_len, "'material'"), &
    var_info_t('conserve', 'c', 1, name_len, "'mass_energy'"), &
    var_info_t('rk_order', 'i', 1, 0, '3'), &
    var_info_t('cfl', 'r', 1, 0, '0.5'), &
    var_info_t('dt_max', 'r', 1, 0, '1.0e-7'), &
    var_info_t('gfm_probe', 'c', 1, name_len, "'auto'"), &
    var_info_t('reinit_every', 'i', 1, 0, '5'), &
    var_info_t('band', 'i', 1, 0, '6'), &
    var_info_t('contact_kappa', 'r', 1, 0, '1.0')]
  type(var_info_t), parameter :: physics_vars(4) = [ &
    var_info_t('strength', 'l', 1, 0, '.true.'), &
    var_info_t('thermal', 'l', 1, 0, '.true.'), &
    var_info_t('heat_conduction', 'l', 1, 0, '.false.'), &
    var_info_t('reaction', 'l', 1, 0, '.false.')]
  type(var_info_t), parameter :: material_vars(28) = [ &
    var_info_t('name', 'c', 1, name_len, "'water'"), &
    var_info_t('eos', 'c', 1, name_len, "'stiffened_gas'"), &
    var_info_t('rho0', 'r', 1, 0, '1000.0'), &
    var_info_t('p0', 'r', 1, 0, '1.0e5'), &
    var_info_t('gamma', 'r', 1, 0, '1.4'), &
    var_info_t('p_inf', 'r', 1, 0, '6.0e8'), &
    var_info_t('c0', 'r', 1, 0, '3940.0'), &
    var_info_t('s', 'r', 1, 0, '1.49'), &
    var_info_t('gruneisen', 'r', 1, 0, '2.0'), &
    var_info_t('cv', 'r', 1, 0, '717.5'), &
    var_info_t('T0', 'r', 1, 0, '293.15'), &
    var_info_t('bulk_modulus', 'r', 1, 0, '12.5e9'), &
    var_info_t('poly_a', 'r', 1, 0, '22.0e9'), &
    var_info_t('poly_b', 'r', 1, 0, '15.0e9'), &
    var_info_t('strength_model', 'c', 1, name_len, "'johnson_cook'"), &
    var_info_t('shear_modulus', 'r', 1, 0, '43.33e9'), &
    var_info_t('yield0', 'r', 1, 0, '0.4e9'), &
    var_info_t('hardening_modulus', 'r', 1, 0, '0.1e9'), &
    var_info_t('jc_b', 'r', 1, 0, '0.177e9'), &
    var_info_t('jc_n', 'r', 1, 0, '1.0'), &
    var_info_t('jc_c', 'r', 1, 0, '0.025'), &
    var_info_t('jc_m', 'r', 1, 0, '1.09'), &
    var_info_t('t_melt', 'r', 1, 0, '1358.0'), &
    var_info_t('eps_rate0', 'r', 1, 0, '1.0'), &
    var_info_t('vp_chi', 'r', 1, 0, '1.08'), &
    var_info_t('vp_m', 'r', 1, 0, '-0.79'), &
    var_info_t('vp_n', 'r', 1, 0, '1.58'), &
    var_info_t('taylor_quinney', 'r', 1, 0, '0.9')]
  type(var_info_t), parameter :: body_vars(15) = [ &
    var_info_t('name', 'c', 1, name_len, "'projectile'"), &
    var_info_t('material', 'c', 1, name_len, "'copper'"), &
    var_info_t('shape', 'c', 1, name_len, "'sphere'"), &
    var_info_t('center', 'r', 3, 0, '0.5, 0.5, 0.0'), &
    var_info_t('radius', 'r', 1, 0, '0.1'), &
    var_info_t('length', 'r', 1, 0, '0.2'), &
    var_info_t('axis', 'r', 3, 0, '0.0, 0.0, 1.0'), &
    var_info_t('lo', 'r', 3, 0, '0.0, 0.0, 0.0'), &
    var_info_t('hi', 'r', 3, 0, '0.5, 1.0, 1.0'), &
    var_info_t('velocity', 'r', 3, 0, '1000.0, 0.0, 0.0'), &
    var_info_t('rho', 'r', 1, 0, '1000.0'), &
    var_info_t('p', 'r', 1, 0, '1.0e5'), &
    var_info_t('T', 'r', 1, 0, '300.0'), &
    var_info_t('amplitude', 'r', 1, 0, '0.2'), &
    var_info_t('wavevector', 'r', 3, 0, '1.0, 0.0, 0.0')]
  type(var_info_t), parameter :: output_vars(5) = [ &
    var_info_t('plot_dt', 'r', 1, 0, '1.0e-3'), &
    var_info_t('plot_every', 'i', 1, 0, '100'), &
    var_info_t('checkpoint_every', 'i', 1, 0, '1000'), &
    var_info_t('history_every', 'i', 1, 0, '10'), &
    var_info_t('fields', 'c', max_fields, name_len, "'rho', 'u', 'p'")]

  !> the deck errors found so far (lines), and the variables they name ('&group var',
  !> without an index), which get no second error
  character(len=:), allocatable :: err_text
  character(len=:), allocatable :: err_keys
  integer :: n_errors = 0

contains

  !> Start a deck read with no errors.
  subroutine deck_errors_begin()
    err_text = ''
    err_keys = '|'
    n_errors = 0
  end subroutine deck_errors_begin

  !> Record `ERROR <base> <where>: <why> (typical value <typical>)` and return, unless the
  !> variable of `where` has had an error already.
  subroutine fail(base, where, why, typical)
    character(len=*), intent(in) :: base, where, why, typical
    if (.not. allocated(err_text)) call deck_errors_begin()
    if (deck_has_error(where)) return
    call deck_error_mark(where)
    if (n_errors > 0) err_text = err_text // new_line('a')
    err_text = err_text // error_line(base, where, why, typical)
    n_errors = n_errors + 1
  end subroutine fail

  !> fail(), then stop every rank with every error found so far.
  subroutine fail_now(base, where, why, typical)
    character(len=*), intent(in) :: base, where, why, typical
    call fail(base, where, why, typical)
    call deck_errors_stop()
  end subroutine fail_now

  !> Collective: when errors were found, print them, one a line, and stop every rank.
  subroutine deck_errors_stop()
    if (.not. allocated(err_text)) return
    call stop_collective(err_text, n_errors == 0)
  end subroutine deck_errors_stop

  integer function deck_error_count() result(n)
    n = n_errors
  end function deck_error_count

  !> '&group var' of where (an index or a trailing word dropped), or '' outside a group.
  function error_key(where) result(key)
    character(len=*), intent(in) :: where
    character(len=:), allocatable :: key
    integer :: paren
    key = to_lower(trim(adjustl(where)))
    paren = index(key, '(')
    if (paren > 0) key = key(1:paren - 1)
  end function error_key

  !> Take the variable of where ('&group var') as wrong: it gets no error of its own later.
  !> '&group *' takes every variable of the group (a group missing or misspelled).
  subroutine deck_error_mark(where)
    character(len=*), intent(in) :: where
    if (.not. allocated(err_keys)) call deck_errors_begin()
    if (index(error_key(where), ' ') == 0) return
    if (.not. deck_has_error(where)) err_keys = err_keys // error_key(where) // '|'
  end subroutine deck_error_mark

  !> Whether the variable of where ('&group var') has had an error, or its whole group.
  logical function deck_has_error(where) result(has)
    character(len=*), intent(in) :: where
    character(len=:), allocatable :: key
    integer :: blank
    has = .false.
    if (.not. allocated(err_keys)) return
    key = error_key(where)
    blank = index(key, ' ')
    if (blank == 0) return
    has = index(err_keys, '|' // key // '|') > 0 .or. &
      index(err_keys, '|' // key(1:blank) // '*|') > 0
  end function deck_has_error

  !> `ERROR <base> <where>: <why> (typical value <typical>)`, without `<where>` or the
  !> parenthesis when they are blank.
  function error_line(base, where, why, typical) result(line)
    character(len=*), intent(in) :: base, where, why, typical
    character(len=:), allocatable :: line
    line = 'ERROR ' // base
    if (len_trim(where) > 0) line = line // ' ' // trim(where)
    line = line // ': ' // why
    if (len_trim(typical) > 0) line = line // ' (typical value ' // trim(typical) // ')'
  end function error_line

  !> fail() for variable vname (possibly with an index) of group gname, with its typical
  !> value from the tables.
  subroutine bad(base, gname, vname, why)
    character(len=*), intent(in) :: base, gname, vname, why
    type(var_info_t) :: info
    integer :: k, paren
    paren = index(vname // '(', '(')
    k = var_index(group_vars(gname), to_lower(vname(1:paren - 1)))
    info = var_info_t()
    if (k > 0) info = group_var(gname, k)
    call fail(base, '&' // gname // ' ' // vname, why, info%typical)
  end subroutine bad

  function group_vars(gname) result(vars)
    character(len=*), intent(in) :: gname
    type(var_info_t), allocatable :: vars(:)
    select case (gname)
    case ('run')
      allocate(vars, source=run_vars)
    case ('domain')
      allocate(vars, source=domain_vars)
    case ('numerics')
      allocate(vars, source=numerics_vars)
    case ('physics')
      allocate(vars, source=physics_vars)
    case ('material')
      allocate(vars, source=material_vars)
    case ('body')
      allocate(vars, source=body_vars)
    case default
      allocate(vars, source=output_vars)
    end select
  end function group_vars

  type(var_info_t) function group_var(gname, k) result(info)
    character(len=*), intent(in) :: gname
    integer, intent(in) :: k
    type(var_info_t), allocatable :: vars(:)
    allocate(vars, source=group_vars(gname))
    info = vars(k)
  end function group_var

  !> The first other group that knows a variable called name, or ''.
  function group_of(name, except) result(r)
    character(len=*), intent(in) :: name, except
    character(len=:), allocatable :: r
    character(len=8), parameter :: order(7) = [character(len=8) :: 'run', 'domain', &
      'numerics', 'physics', 'material', 'body', 'output']
    integer :: k
    do k = 1, size(order)
      r = trim(order(k))
      if (r == except) cycle
      if (var_index(group_vars(r), name) > 0) return
    end do
    r = ''
  end function group_of

  integer function var_index(vars, name) result(k)
    type(var_info_t), intent(in) :: vars(:)
    character(len=*), intent(in) :: name
    do k = 1, size(vars)
      if (to_lower(trim(vars(k)%name)) == name) return
    end do
    k = 0
  end function var_index

end module m_deck_schema
