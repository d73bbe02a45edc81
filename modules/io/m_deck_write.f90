!> The output folder and the resolved deck (DESIGN section 6): deck_prepare_output checks
!> out_dir (results of an earlier run are kept unless overwrite is set) and the restart
!> file, creates the folder and writes out_dir/deck.nml there; deck_write_resolved writes a
!> configuration back as a deck, every value with the defaults filled in, so that deck_read
!> of it gives back the same configuration bit for bit. It neither reads nor checks a deck
!> (m_deck, m_deck_check).
module m_deck_write
  use m_kinds, only: path_len, line_len
  use m_config, only: config_t, max_materials, max_bodies
  use m_errors, only: stop_collective, fatal
  use m_comm, only: comm_is_root
  use m_deck_text, only: shell_quoted, base_name, dir_name, normal_path
  use m_deck_parse, only: deck_var_t, value_text
  use m_deck_schema, only: error_line, deck_table, group_names
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

  !> Write cfg as a deck: every group, every variable of the table in its order, defaults
  !> filled in; deck_read gives back the same cfg. Reals left unset on purpose are written as
  !> comments. Plain I/O on the calling rank; ios (when present) receives the status instead
  !> of stopping.
  subroutine deck_write_resolved(cfg, path, ios)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(in) :: path
    integer, intent(out), optional :: ios
    type(config_t), target, allocatable :: c
    type(deck_var_t), allocatable :: vars(:)
    character(len=line_len) :: msg
    integer :: u, stat, i, k, g
    msg = ''
    open(newunit=u, file=trim(path), status='replace', action='write', iostat=stat, &
      iomsg=msg)
    if (stat == 0) then
      write(u, '(a)') '! Resolved SABRE deck: every value of ' // trim(cfg%deck_file) &
        // ' with the defaults filled in.'
      c = cfg
      do g = 1, size(group_names)
        do i = 1, merge(c%n_materials, merge(c%n_bodies, 1, group_names(g) == 'body'), &
          group_names(g) == 'material')
          call deck_table(c, c%materials(min(i, max_materials)), c%bodies(min(i, max_bodies)), vars)
          write(u, '(a)') '&' // trim(group_names(g))
          do k = 1, size(vars)
            if (vars(k)%group /= group_names(g)) cycle
            if (len(value_text(vars(k))) == 0) then
              write(u, '(a)') '  ! ' // trim(vars(k)%name) // ' is unset'
            else
              write(u, '(a)') '  ' // trim(vars(k)%name) // ' = ' // value_text(vars(k))
            end if
          end do
          write(u, '(a)') '/'
        end do
      end do
      close(u, iostat=stat, iomsg=msg)
    end if
    if (present(ios)) then
      ios = stat
    else if (stat /= 0) then
      call fatal('deck_write_resolved', 'cannot write ' // trim(path) // ': ' // trim(msg))
    end if
  end subroutine deck_write_resolved

end module m_deck_write
