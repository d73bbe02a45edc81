!> The output folder and the resolved deck (DESIGN section 6): deck_prepare_output checks
!> out_dir (results of an earlier run are kept unless overwrite is set) and the restart
!> file, creates the folder and writes out_dir/deck.nml there; deck_write_resolved writes a
!> configuration back as a deck, every value with the defaults filled in, so that deck_read
!> of it gives back the same configuration bit for bit. It neither reads nor checks a deck
!> (m_deck, m_deck_check).
module m_deck_write
  use m_kinds, only: wp, path_len, line_len
  use m_config, only: config_t, is_set
  use m_errors, only: stop_collective, fatal
  use m_comm, only: comm_is_root
  use m_deck_text, only: int_text, real_text, quoted, shell_quoted, base_name, dir_name, &
    normal_path
  use m_deck_schema, only: error_line
  implicit none
  private
  public :: deck_prepare_output, deck_write_resolved

contains

  !> Check out_dir, create it, and write the resolved deck there (out_dir/deck.nml).
  !> Collective. Results already in out_dir stop the run unless overwrite is set or the
  !> run restarts from a checkpoint in that same folder (a restart continues a run).
  subroutine deck_prepare_output(cfg)
    type(config_t), intent(in) :: cfg
    character(len=:), allocatable :: base, dir
    character(len=2 * path_len + line_len) :: msg
    logical :: ok, exists, continuing
    integer :: ios, stat, cmd_stat
    ok = .true.
    msg = ''
    if (comm_is_root()) then
      base = base_name(cfg%deck_file)
      dir = normal_path(cfg%out_dir)
      if (len_trim(cfg%restart) > 0) then
        inquire(file=trim(cfg%restart), exist=exists)
        if (.not. exists) call refuse('&run restart', "no such checkpoint file '" &
          // trim(cfg%restart) // "'", "'out/sod/chk_000100.h5'")
      end if
      continuing = .false.
      if (len_trim(cfg%restart) > 0) continuing = (dir_name(cfg%restart) == dir)
      if (ok .and. .not. cfg%overwrite .and. .not. continuing) then
        if (holds_results(dir)) call refuse('&run out_dir', "'" // trim(cfg%out_dir) &
          // "' already holds results (set overwrite = .true. or choose another out_dir)", '')
      end if
      if (ok .and. cfg%overwrite .and. .not. continuing) then
        ! a fresh run replaces the results it overwrites: an old plot file with a later step
        ! number must not pass for this run's last one
        call execute_command_line('rm -f ' // shell_quoted(dir) // '/run.log ' // &
          shell_quoted(dir) // '/history.csv ' // shell_quoted(dir) // '/plot_*.h5 ' // &
          shell_quoted(dir) // '/plot_*.xmf ' // shell_quoted(dir) // '/chk_*.h5', &
          exitstat=stat, cmdstat=cmd_stat)
      end if
      if (ok) then
        call execute_command_line('mkdir -p ' // shell_quoted(dir), exitstat=stat, &
          cmdstat=cmd_stat)
        if (stat /= 0 .or. cmd_stat /= 0) call refuse('&run out_dir', "cannot create '" &
          // dir // "' (check the path and permissions)", "'out/sod'")
      end if
      if (ok) then
        call deck_write_resolved(cfg, dir // '/deck.nml', ios)
        if (ios /= 0) call refuse('&run out_dir', "cannot write '" // dir &
          // "/deck.nml' (check permissions)", "'out/sod'")
      end if
    end if
    call stop_collective(msg, ok)

  contains

    subroutine refuse(where, why, typical)
      character(len=*), intent(in) :: where, why, typical
      if (.not. ok) return
      ok = .false.
      msg = error_line(base, where, why, typical)
    end subroutine refuse

  end subroutine deck_prepare_output

  !> Whether a folder holds results of a run: run.log, history.csv, plot_*.h5, chk_*.h5.
  logical function holds_results(dir)
    character(len=*), intent(in) :: dir
    integer :: stat, cmd_stat
    logical :: exists
    inquire(file=dir // '/run.log', exist=holds_results)
    inquire(file=dir // '/history.csv', exist=exists)
    holds_results = holds_results .or. exists
    if (holds_results) return
    call execute_command_line('ls -1A ' // shell_quoted(dir) // ' 2>/dev/null | grep -Eq ' &
      // "'^(plot_.*|chk_.*)\.h5$'", exitstat=stat, cmdstat=cmd_stat)
    holds_results = (cmd_stat == 0 .and. stat == 0)
  end function holds_results

  !> Write cfg as a deck: every group, every value, defaults filled in; deck_read gives
  !> back the same cfg. Values left unset on purpose are written as comments. Plain I/O on
  !> the calling rank; ios (when present) receives the status instead of stopping.
  subroutine deck_write_resolved(cfg, path, ios)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(in) :: path
    integer, intent(out), optional :: ios
    character(len=line_len) :: msg
    integer :: u, stat, i
    msg = ''
    open(newunit=u, file=trim(path), status='replace', action='write', iostat=stat, &
      iomsg=msg)
    if (stat == 0) then
      write(u, '(a)') '! Resolved SABRE deck: every value of ' // trim(cfg%deck_file) &
        // ' with the defaults filled in.'
      write(u, '(a)') '&run'
      call put(u, 'title', quoted(cfg%title))
      call put_real(u, 't_end', cfg%t_end)
      call put(u, 'max_steps', int_text(cfg%max_steps))
      call put_real(u, 'wall_limit', cfg%wall_limit)
      call put(u, 'out_dir', quoted(cfg%out_dir))
      call put(u, 'overwrite', logical_text(cfg%overwrite))
      call put(u, 'restart', quoted(cfg%restart))
      write(u, '(a)') '/', '&domain'
      call put(u, 'ndim', int_text(cfg%ndim))
      call put(u, 'geometry', quoted(cfg%geometry))
      call put(u, 'lo', reals_text(cfg%lo))
      call put(u, 'hi', reals_text(cfg%hi))
      call put(u, 'cells', ints_text(cfg%cells))
      call put(u, 'block', ints_text(cfg%block))
      call put(u, 'bc_lo', strings_text(cfg%bc_lo))
      call put(u, 'bc_hi', strings_text(cfg%bc_hi))
      call put(u, 'bc_velocity', reals_text(cfg%bc_velocity))
      call put_real(u, 'bc_rise_time', cfg%bc_rise_time)
      call put(u, 'base_material', quoted(cfg%base_material))
      write(u, '(a)') '/', '&numerics'
      call put(u, 'scheme', quoted(cfg%scheme))
      call put(u, 'flux', quoted(cfg%flux))
      call put(u, 'scalar_flux', quoted(cfg%scalar_flux))
      call put(u, 'surface_flux', quoted(cfg%surface_flux))
      call put(u, 'conserve', quoted(cfg%conserve))
      call put(u, 'rk_order', int_text(cfg%rk_order))
      call put_real(u, 'cfl', cfg%cfl)
      call put_real(u, 'dt_max', cfg%dt_max)
      call put(u, 'gfm_probe', quoted(cfg%gfm_probe))
      call put(u, 'reinit_every', int_text(cfg%reinit_every))
      call put(u, 'band', int_text(cfg%band))
      call put_real(u, 'contact_kappa', cfg%contact_kappa)
      write(u, '(a)') '/', '&physics'
      call put(u, 'strength', logical_text(cfg%strength))
      call put(u, 'thermal', logical_text(cfg%thermal))
      call put(u, 'heat_conduction', logical_text(cfg%heat_conduction))
      call put(u, 'reaction', logical_text(cfg%reaction))
      write(u, '(a)') '/'
      do i = 1, cfg%n_materials
        associate(m => cfg%materials(i))
          write(u, '(a)') '&material'
          call put(u, 'name', quoted(m%name))
          call put(u, 'eos', quoted(m%eos))
          call put_real(u, 'rho0', m%rho0)
          call put_real(u, 'p0', m%p0)
          call put_real(u, 'gamma', m%gamma)
          call put_real(u, 'p_inf', m%p_inf)
          call put_real(u, 'c0', m%c0)
          call put_real(u, 's', m%s)
          call put_real(u, 'gruneisen', m%gruneisen)
          call put_real(u, 'cv', m%cv)
          call put_real(u, 'T0', m%T0)
          call put_real(u, 'bulk_modulus', m%bulk_modulus)
          call put_real(u, 'poly_a', m%poly_a)
          call put_real(u, 'poly_b', m%poly_b)
          call put(u, 'strength_model', quoted(m%strength_model))
          call put_real(u, 'shear_modulus', m%shear_modulus)
          call put_real(u, 'yield0', m%yield0)
          call put_real(u, 'hardening_modulus', m%hardening_modulus)
          call put_real(u, 'jc_b', m%jc_b)
          call put_real(u, 'jc_n', m%jc_n)
          call put_real(u, 'jc_c', m%jc_c)
          call put_real(u, 'jc_m', m%jc_m)
          call put_real(u, 't_melt', m%t_melt)
          call put_real(u, 'eps_rate0', m%eps_rate0)
          call put_real(u, 'vp_chi', m%vp_chi)
          call put_real(u, 'vp_m', m%vp_m)
          call put_real(u, 'vp_n', m%vp_n)
          call put_real(u, 'taylor_quinney', m%taylor_quinney)
          write(u, '(a)') '/'
        end associate
      end do
      do i = 1, cfg%n_bodies
        associate(b => cfg%bodies(i))
          write(u, '(a)') '&body'
          call put(u, 'name', quoted(b%name))
          call put(u, 'material', quoted(b%material))
          call put(u, 'shape', quoted(b%shape))
          call put(u, 'center', reals_text(b%center))
          call put_real(u, 'radius', b%radius)
          call put_real(u, 'length', b%length)
          call put(u, 'axis', reals_text(b%axis))
          call put(u, 'lo', reals_text(b%lo))
          call put(u, 'hi', reals_text(b%hi))
          call put(u, 'velocity', reals_text(b%velocity))
          call put_real(u, 'rho', b%rho)
          call put_real(u, 'p', b%p)
          call put_real(u, 'T', b%T)
          call put_real(u, 'amplitude', b%amplitude)
          call put(u, 'wavevector', reals_text(b%wavevector))
          write(u, '(a)') '/'
        end associate
      end do
      write(u, '(a)') '&output'
      call put_real(u, 'plot_dt', cfg%plot_dt)
      call put(u, 'plot_every', int_text(cfg%plot_every))
      call put(u, 'checkpoint_every', int_text(cfg%checkpoint_every))
      call put(u, 'history_every', int_text(cfg%history_every))
      call put(u, 'fields', strings_text(cfg%fields(1:max(cfg%n_fields, 1))))
      write(u, '(a)') '/'
      close(u, iostat=stat, iomsg=msg)
    end if
    if (present(ios)) then
      ios = stat
    else if (stat /= 0) then
      call fatal('deck_write_resolved', 'cannot write ' // trim(path) // ': ' // trim(msg))
    end if
  end subroutine deck_write_resolved

  subroutine put(u, name, text)
    integer, intent(in) :: u
    character(len=*), intent(in) :: name, text
    write(u, '(a)') '  ' // name // ' = ' // text
  end subroutine put

  subroutine put_real(u, name, x)
    integer, intent(in) :: u
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: x
    if (.not. is_set(x)) then
      write(u, '(a)') '  ! ' // name // ' is unset'
    else
      call put(u, name, real_text(x))
    end if
  end subroutine put_real

  function reals_text(x) result(r)
    real(wp), intent(in) :: x(:)
    character(len=:), allocatable :: r
    integer :: k
    r = real_text(x(1))
    do k = 2, size(x)
      r = r // ', ' // real_text(x(k))
    end do
  end function reals_text

  function ints_text(x) result(r)
    integer, intent(in) :: x(:)
    character(len=:), allocatable :: r
    integer :: k
    r = int_text(x(1))
    do k = 2, size(x)
      r = r // ', ' // int_text(x(k))
    end do
  end function ints_text

  function strings_text(x) result(r)
    character(len=*), intent(in) :: x(:)
    character(len=:), allocatable :: r
    integer :: k
    r = quoted(x(1))
    do k = 2, size(x)
      r = r // ', ' // quoted(x(k))
    end do
  end function strings_text

  function logical_text(x) result(r)
    logical, intent(in) :: x
    character(len=:), allocatable :: r
    r = merge('.true. ', '.false.', x)
    r = trim(r)
  end function logical_text

end module m_deck_write
