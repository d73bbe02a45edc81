!> Checkpoints and restarts (DESIGN section 7): chk_NNNNNN.h5 holds the conserved state, the
!> clock and what a restart needs to continue bit for bit (the cut-cell content and budget
!> totals); output_restart_check checks a checkpoint against the deck before any state is
!> read, output_restart reads the state back. Plot files and history rows are m_output's.
module m_checkpoint
  use m_kinds, only: wp, name_len
  use m_simulation, only: sim_t
  use m_hdf5_io, only: h5_file_t, h5_create, h5_open_read, h5_close, h5_write_attr, &
    h5_read_attr, h5_write_field, h5_read_field, h5_read_field_halo, h5_write_text, &
    h5_has_attr, h5_is_hdf5, h5_exists
  use m_errors, only: stop_collective, error_line, log_line
  use m_text, only: base_name, int_text
  use m_output, only: step_file_name
  use m_hotspot, only: hot_pack, hot_unpack
  implicit none
  private
  public :: output_checkpoint, output_restart, output_restart_check

  !> the version of the checkpoint layout this code writes and reads; a checkpoint without
  !> the attribute was written before it existed (version 0, read the same way)
  integer, parameter :: checkpoint_version = 1
  !> which per-variable fields block_fields moves: the state's variables, or the cut-cell
  !> phase's content
  integer, parameter :: state_fields = 1, content_fields = 2

contains

  !> The prefix of cut phase k's fields and attributes in a checkpoint: cut for the first,
  !> cut<k> for each after it (m_gfm_cut_setup: one for each cut phase).
  pure function cut_prefix(k) result(pre)
    integer, intent(in) :: k
    character(len=16) :: pre
    pre = 'cut'
    if (k > 1) write(pre, '(a,i0)') 'cut', k
  end function cut_prefix

  !> Name of cut phase k's content variable m in a checkpoint: /cut/c<m> (/cut<k>/c<m>).
  pure function content_names(k, m) result(name)
    integer, intent(in) :: k, m
    character(len=name_len) :: name
    write(name, '(a,i0)') '/' // trim(cut_prefix(k)) // '/c', m
  end function content_names

  !> Name of cut phase k's fractions at the step's end (m_gfm_cut alpha_n): /cut/alpha_n.
  pure function fractions_name(k) result(name)
    integer, intent(in) :: k
    character(len=name_len) :: name
    name = '/' // trim(cut_prefix(k)) // '/alpha_n'
  end function fractions_name

  !> Name of state variable m in a checkpoint: /state/q<m> (flow variables, then level sets).
  pure function state_names(m) result(name)
    integer, intent(in) :: m
    character(len=name_len) :: name
    write(name, '(a,i0)') '/state/q', m
  end function state_names

  !> chk_NNNNNN.h5: the conserved state and the clock, enough for a bit-identical restart.
  subroutine output_checkpoint(sim, deck_text)
    type(sim_t), intent(inout) :: sim
    character(len=*), intent(in) :: deck_text
    type(h5_file_t) :: f
    real(wp), allocatable :: data(:, :, :, :)
    integer :: b, n(3), k
    character(len=16) :: pre
    call h5_create(f, step_file_name(sim, 'chk', sim%clk%step, '.h5'), sim%lay)
    call h5_write_attr(f, 'time', sim%clk%time)
    call h5_write_attr(f, 'step', sim%clk%step)
    call h5_write_attr(f, 'plot_count', sim%clk%plot_count)
    call h5_write_attr(f, 'last_plot_step', sim%clk%last_plot_step)
    call h5_write_attr(f, 'next_plot_time', sim%clk%next_plot_time)
    call h5_write_attr(f, 'dt_first', sim%clk%dt_first)
    call h5_write_attr(f, 'nvar', sim%ph%nvar)
    call h5_write_attr(f, 'checkpoint_version', checkpoint_version)
    if (sim%fix%on) then
      ! the conservation fix's state (m_step_after::step_corrections)
      call h5_write_attr(f, 'fix_content', reshape(sim%fix%content, [size(sim%fix%content)]))
      call h5_write_attr(f, 'fix_taken', reshape(sim%fix%taken, [size(sim%fix%taken)]))
      call h5_write_attr(f, 'fix_content0', sim%fix%content0)
      call h5_write_attr(f, 'fix_clamped', sim%fix%clamped)
      call h5_write_attr(f, 'fix_open_cells', sim%fix%open_cells)
      call h5_write_attr(f, 'fix_crossing', sim%fix%crossing)
    end if
    call block_fields(f, sim, state_fields, .true.)
    ! the hot-spot peaks so far (run.json's summary covers the whole run)
    if (sim%hot%on) call h5_write_attr(f, 'hotspots', hot_pack(sim%hot))
    do k = 1, size(sim%cut)
      if (.not. sim%cut(k)%on) exit
      pre = cut_prefix(k)
      associate (cut => sim%cut(k))
        ! each cut phase's content (its states do not give it back: a cut cell's state
        ! has the density of the material beside it) and its budget so far (m_gfm_cut)
        call h5_write_attr(f, trim(pre) // '_stranded', cut%stranded)
        call h5_write_attr(f, trim(pre) // '_crossed', cut%crossed)
        call h5_write_attr(f, trim(pre) // '_closing', cut%closing)
        call h5_write_attr(f, trim(pre) // '_held', cut%held)
        if (size(sim%cut) > 1) call h5_write_attr(f, trim(pre) // '_exchanged', cut%exchanged)
        call block_fields(f, sim, content_fields, .true., k)
        ! the fractions the states were formed at (the void's level set has followed the
        ! content since: cut_follow), which the next step's exchange of filled cells
        ! compares with (cut_donate)
        data = field_buffer(sim)
        do b = 1, size(sim%blocks)
          n = sim%blocks(b)%n
          data(1:n(1), 1:n(2), 1:n(3), b) = cut%alpha_n(1:n(1), 1:n(2), 1:n(3), b)
        end do
        call h5_write_field(f, trim(fractions_name(k)), sim%lay, block_ids(sim), data)
      end associate
    end do
    call h5_write_text(f, '/deck', deck_text)
    call h5_close(f)
    call log_line('checkpoint ' // trim(step_file_name(sim, 'chk', sim%clk%step, '.h5')))
  end subroutine output_checkpoint

  !> Refuse, on every rank and before anything is written, a restart file that is missing,
  !> not HDF5, not a SABRE checkpoint (a plot file, another code's file), of a later
  !> checkpoint version, or for another grid or state than the deck's.
  subroutine output_restart_check(sim, path)
    type(sim_t), intent(in) :: sim
    character(len=*), intent(in) :: path
    character(len=*), parameter :: needed(5) = [character(len=10) :: 'cells', 'nvar', 'step', &
      'time', 'dt_first']
    type(h5_file_t) :: f
    character(len=:), allocatable :: why, name
    integer :: cells(3), nvar, version, k
    real(wp) :: lo(3), hi(3)
    logical :: exists
    name = "'" // trim(path) // "'"
    why = ''
    inquire(file=trim(path), exist=exists)
    if (.not. exists) then
      why = 'no such checkpoint file ' // name
    else if (.not. h5_is_hdf5(path)) then
      why = name // ' is not a SABRE checkpoint (not an HDF5 file; restart names a ' // &
        'chk_NNNNNN.h5 file)'
    else
      call h5_open_read(f, path)
      do k = 1, size(needed)
        if (len(why) > 0) exit
        if (.not. h5_has_attr(f, trim(needed(k)))) why = name // &
          ' is not a SABRE checkpoint (no attribute ' // trim(needed(k)) // '; a plot file?)'
      end do
      if (len(why) == 0) then
        if (.not. h5_exists(f, '/state')) why = name // &
          ' is not a SABRE checkpoint (no /state group)'
      end if
      if (len(why) == 0) then
        version = 0
        if (h5_has_attr(f, 'checkpoint_version')) &
          call h5_read_attr(f, 'checkpoint_version', version)
        call h5_read_attr(f, 'cells', cells)
        call h5_read_attr(f, 'nvar', nvar)
        call h5_read_attr(f, 'lo', lo)
        call h5_read_attr(f, 'hi', hi)
        if (version > checkpoint_version) then
          why = name // ' is a version ' // int_text(version) // ' checkpoint; this SABRE ' &
            // 'reads versions up to ' // int_text(checkpoint_version)
        else if (any(cells /= sim%lay%cells)) then
          why = name // ' is for another grid: cells ' // dims(cells) // ', the deck has ' &
            // dims(sim%lay%cells) // ' (restart with the &domain of the run that wrote it)'
        else if (any(abs(lo - sim%lay%lo) > 1.0e-12_wp * max(abs(lo), abs(hi - lo))) .or. &
          any(abs(hi - sim%lay%hi) > 1.0e-12_wp * max(abs(hi), abs(hi - lo)))) then
          why = name // ' is for another domain (lo, hi differ from the deck''s)'
        else if (nvar /= sim%ph%nvar) then
          why = name // ' is for another state: ' // int_text(nvar) // ' variables per ' // &
            'cell, the deck has ' // int_text(sim%ph%nvar) // ' (other materials, bodies or ' // &
            'effects)'
        end if
      end if
      call h5_close(f)
    end if
    call stop_collective(error_line(base_name(sim%cfg%deck_file), '&run restart', why, &
      "'out/sod/chk_000100.h5'"), len(why) == 0)

  contains

    function dims(n) result(t)
      integer, intent(in) :: n(3)
      character(len=:), allocatable :: t
      t = int_text(n(1)) // ' x ' // int_text(n(2)) // ' x ' // int_text(n(3))
    end function dims

  end subroutine output_restart_check

  subroutine output_restart(sim, path)
    type(sim_t), intent(inout) :: sim
    character(len=*), intent(in) :: path
    type(h5_file_t) :: f
    real(wp), allocatable :: fix(:), hot(:)
    logical :: ok
    integer :: k
    character(len=16) :: pre
    ! that the file is a checkpoint for this grid and state was checked before anything was
    ! written (output_restart_check)
    call h5_open_read(f, path)
    call h5_read_attr(f, 'time', sim%clk%time)
    call h5_read_attr(f, 'step', sim%clk%step)
    call h5_read_attr(f, 'plot_count', sim%clk%plot_count)
    call h5_read_attr(f, 'last_plot_step', sim%clk%last_plot_step)
    call h5_read_attr(f, 'next_plot_time', sim%clk%next_plot_time)
    call h5_read_attr(f, 'dt_first', sim%clk%dt_first)
    if (sim%fix%on) then
      allocate(fix(size(sim%fix%content)))
      call h5_read_attr(f, 'fix_content', fix)
      sim%fix%content = reshape(fix, shape(sim%fix%content))
      call h5_read_attr(f, 'fix_taken', fix)
      sim%fix%taken = reshape(fix, shape(sim%fix%taken))
      call h5_read_attr(f, 'fix_content0', sim%fix%content0)
      call h5_read_attr(f, 'fix_clamped', sim%fix%clamped)
      call h5_read_attr(f, 'fix_open_cells', sim%fix%open_cells)
      ! Checkpoints from before the open-side rule lack it: no phase was crossing then.
      sim%fix%crossing = 0.0_wp
      if (h5_has_attr(f, 'fix_crossing')) then
        call h5_read_attr(f, 'fix_crossing', sim%fix%crossing)
      else
        call log_line('restart: ' // trim(path) // ' has no fix_crossing (written before ' // &
          'the open-side rule of the conservation fix): no phase taken as crossing')
      end if
    end if
    call block_fields(f, sim, state_fields, .false.)
    if (sim%hot%on) then
      ok = h5_has_attr(f, 'hotspots')
      if (ok) then
        hot = hot_pack(sim%hot)   ! (the length this scene's peaks take)
        call h5_read_attr(f, 'hotspots', hot)
        call hot_unpack(sim%hot, hot, ok)
      end if
      if (.not. ok) call log_line('restart: ' // trim(path) // ' has no hot-spot peaks of ' &
        // 'this scene (written before them, or with other voids): run.json summarises from ' &
        // 'the restart on')
    end if
    do k = 1, size(sim%cut)
      sim%cut(k)%restored = .false.
      sim%cut(k)%restored_fractions = .false.
      if (.not. sim%cut(k)%on) cycle
      pre = cut_prefix(k)
      associate (cut => sim%cut(k))
        if (h5_exists(f, trim(content_names(k, 1)))) then
          call h5_read_attr(f, trim(pre) // '_stranded', cut%stranded)
          call h5_read_attr(f, trim(pre) // '_crossed', cut%crossed)
          ! (a checkpoint written before the closing exchange counts from the restart on)
          cut%closing = 0.0_wp
          if (h5_has_attr(f, trim(pre) // '_closing')) call h5_read_attr(f, &
            trim(pre) // '_closing', &
            cut%closing)
          cut%held = 0.0_wp
          if (h5_has_attr(f, trim(pre) // '_held')) call h5_read_attr(f, &
            trim(pre) // '_held', cut%held)
          cut%exchanged = 0.0_wp
          if (h5_has_attr(f, trim(pre) // '_exchanged')) call h5_read_attr(f, &
            trim(pre) // '_exchanged', cut%exchanged)
          call block_fields(f, sim, content_fields, .false., k)
          cut%restored = .true.
          if (h5_exists(f, trim(fractions_name(k)))) call restore_fractions(k)
        else
          call log_line('restart: ' // trim(path) // ' holds no cut-cell content of phase ' &
            // trim(sim%ph%material(cut%p)) // ' (written without conserve = ''cut_cell''): ' &
            // 'it is taken from the states')
        end if
      end associate
    end do
    call h5_close(f)
    sim%clk%restart_step = sim%clk%step

  contains

    !> The fractions at the checkpoint's step end: each block's own cells, and those of its
    !> neighbours its exchange of filled cells looks at (e cells into the halo, read from the
    !> file rather than exchanged); beyond the domain's sides -1, which the first step
    !> replaces by the fractions of the level set there (m_gfm_stage).
    subroutine restore_fractions(k)
      integer, intent(in) :: k
      real(wp), allocatable :: ext(:, :, :, :)
      integer :: e(3), b, n(3)
      e = max(sim%lay%ng - 1, 0)
      allocate(ext(1-e(1):sim%lay%nmax(1)+e(1), 1-e(2):sim%lay%nmax(2)+e(2), &
        1-e(3):sim%lay%nmax(3)+e(3), size(sim%blocks)))
      ext = -1.0_wp
      call h5_read_field_halo(f, trim(fractions_name(k)), sim%lay, block_ids(sim), e, ext)
      associate (cut => sim%cut(k))
        do b = 1, size(sim%blocks)
          n = sim%blocks(b)%n
          cut%alpha_n(1:n(1), 1:n(2), 1:n(3), b) = ext(1:n(1), 1:n(2), 1:n(3), b)
          if (allocated(cut%ext_n(b)%a)) deallocate(cut%ext_n(b)%a)
          allocate(cut%ext_n(b)%a(1-e(1):n(1)+e(1), 1-e(2):n(2)+e(2), 1-e(3):n(3)+e(3)))
          cut%ext_n(b)%a = ext(1-e(1):n(1)+e(1), 1-e(2):n(2)+e(2), 1-e(3):n(3)+e(3), b)
        end do
        cut%restored_fractions = .true.
      end associate
    end subroutine restore_fractions
  end subroutine output_restart

  !> The fields `which` (state_fields: /state/q<m>, one per state variable; content_fields:
  !> /cut/c<m>, one per flow variable of cut phase k) between this rank's blocks and
  !> checkpoint f: written when `writing`, else read. One list of the fields for the writer
  !> and the reader, so that they keep the same layout.
  subroutine block_fields(f, sim, which, writing, k)
    type(h5_file_t), intent(in) :: f
    type(sim_t), intent(inout), target :: sim
    integer, intent(in) :: which
    logical, intent(in) :: writing
    integer, intent(in), optional :: k   !< the cut phase (content_fields)
    real(wp), allocatable :: data(:, :, :, :)
    real(wp), pointer :: cells(:, :, :)
    integer, allocatable :: ids(:)
    character(len=name_len) :: name
    integer :: m, b, n(3), nfields
    data = field_buffer(sim)
    ids = block_ids(sim)
    nfields = merge(sim%ph%nflow, sim%ph%nvar, which == content_fields)
    do m = 1, nfields
      if (which == content_fields) then
        name = content_names(k, m)
      else
        name = state_names(m)
      end if
      if (.not. writing) call h5_read_field(f, trim(name), sim%lay, ids, data)
      do b = 1, size(sim%blocks)
        n = sim%blocks(b)%n
        if (which == content_fields) then
          cells => sim%cut(k)%c0(1:n(1), 1:n(2), 1:n(3), m, b)
        else
          cells => sim%blocks(b)%q(1:n(1), 1:n(2), 1:n(3), m)
        end if
        if (writing) then
          data(1:n(1), 1:n(2), 1:n(3), b) = cells
        else
          cells = data(1:n(1), 1:n(2), 1:n(3), b)
        end if
      end do
      if (writing) call h5_write_field(f, trim(name), sim%lay, ids, data)
    end do
  end subroutine block_fields

  !> A field of this rank's blocks as m_hdf5_io has it: block k at data(:, :, :, k), at the
  !> largest block extent (the rest 0).
  function field_buffer(sim) result(data)
    type(sim_t), intent(in) :: sim
    real(wp), allocatable :: data(:, :, :, :)
    allocate(data(sim%lay%nmax(1), sim%lay%nmax(2), sim%lay%nmax(3), size(sim%blocks)))
    data = 0.0_wp
  end function field_buffer

  !> The ids of this rank's blocks, in the order of the buffers' blocks.
  pure function block_ids(sim) result(ids)
    type(sim_t), intent(in) :: sim
    integer :: ids(size(sim%blocks))
    integer :: b
    ids = [(sim%blocks(b)%id, b = 1, size(sim%blocks))]
  end function block_ids

end module m_checkpoint
