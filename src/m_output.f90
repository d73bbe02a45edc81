!> What a run writes (DESIGN section 7): plot files (fields + XDMF) and the diagnostics of a
!> history row. The HDF5 calls live in m_hdf5_io; here the solver state becomes named
!> fields. Checkpoints and restarts are m_checkpoint's. Before any of it, output_prepare
!> makes out_dir ready: earlier results are kept unless overwrite is set.
module m_output
  use m_kinds, only: wp, name_len, path_len
  use m_simulation, only: sim_t
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, i_sxx, i_syy, i_szz, i_sxy, i_syz, &
    i_sxz, i_epsp
  use m_elastoplastic, only: primitive_row, solid_temperature
  use m_eos, only: eos_temperature, eos_sound_speed2
  use m_hdf5_io, only: h5_file_t, h5_create, h5_close, h5_write_attr, h5_write_field
  use m_xdmf, only: xdmf_write
  use m_comm, only: comm_sum_by_key, comm_max, comm_sum, comm_is_root
  use m_levelset_bodies, only: ls_region, ls_material
  use m_gfm_cut_budget, only: cut_content
  use m_scene, only: cell_centre
  use m_layout, only: cell_volume
  use m_config, only: config_t, is_set, material_index
  use m_hotspot, only: hot_t, hot_columns, hot_row_start, hot_block, hot_cell, hot_row, &
    hot_nearest, hot_wants
  use m_kinds, only: i8, line_len
  use m_errors, only: stop_collective, error_line
  use m_text, only: base_name, normal_path, dir_name, replaced, int_text
  use m_deck, only: deck_write_resolved
  implicit none
  private
  public :: output_plot, output_prepare
  public :: history_columns, history_values

  public :: step_file_name

contains

  function step_file_name(sim, prefix, step, ext) result(path)
    type(sim_t), intent(in) :: sim
    character(len=*), intent(in) :: prefix, ext
    integer, intent(in) :: step
    character(len=path_len) :: path
    write(path, '(a,"/",a,"_",i6.6,a)') trim(sim%cfg%out_dir), prefix, step, ext
  end function step_file_name

  !> Write plot_NNNNNN.h5 (NNNNNN = step) and its .xmf with the deck's output fields.
  subroutine output_plot(sim)
    type(sim_t), intent(inout) :: sim
    type(h5_file_t) :: f
    character(len=path_len) :: path, xmf
    character(len=name_len), allocatable :: names(:)
    real(wp), allocatable :: data(:, :, :, :)
    integer, allocatable :: ids(:)
    integer :: m, k, l
    if (sim%clk%last_plot_step == sim%clk%step) return
    path = step_file_name(sim, 'plot', sim%clk%step, '.h5')
    ! every block at the largest extent; h5_write_field writes each block's own part
    allocate(data(sim%lay%nmax(1), sim%lay%nmax(2), sim%lay%nmax(3), size(sim%blocks)))
    data = 0.0_wp
    ids = [(sim%blocks(k)%id, k = 1, size(sim%blocks))]
    ! the deck's fields, then the level set of every body (phi_<body>, negative inside)
    names = [sim%cfg%fields(1:sim%cfg%n_fields), &
      (name_of_ls(sim%ls%name(l)), l = 1, sim%ls%n)]
    call h5_create(f, path, sim%lay)
    call h5_write_attr(f, 'time', sim%clk%time)
    call h5_write_attr(f, 'step', sim%clk%step)
    call h5_write_attr(f, 'title', trim(sim%cfg%title))
    do m = 1, size(names)
      if (m <= sim%cfg%n_fields) then
        call field_values(sim, names(m), data)
      else
        do k = 1, size(sim%blocks)
          associate (n => sim%blocks(k)%n)
            data(1:n(1), 1:n(2), 1:n(3), k) = sim%blocks(k)%q(1:n(1), 1:n(2), 1:n(3), &
              sim%ph%ils + m - sim%cfg%n_fields)
          end associate
        end do
      end if
      call h5_write_field(f, '/fields/' // trim(names(m)), sim%lay, ids, data)
    end do
    call h5_close(f)
    k = index(path, '/', back=.true.)
    xmf = path(1:len_trim(path) - 3) // '.xmf'
    call xdmf_write(xmf, path(k + 1:), sim%lay, names, sim%clk%time)
    sim%clk%plot_count = sim%clk%plot_count + 1
    sim%clk%last_plot_step = sim%clk%step
  end subroutine output_plot

  pure function name_of_ls(body) result(name)
    character(len=*), intent(in) :: body
    character(len=name_len) :: name
    name = 'phi_' // trim(body)
  end function name_of_ls

  !> One named field over the interiors of this rank's blocks: in each cell the value of the
  !> phase whose region it is (where none is, the nearest phase's rest or ghost state).
  !> data(:, :, :, b) is block b at the largest block extent; its own part is filled.
  subroutine field_values(sim, name, data)
    type(sim_t), intent(in) :: sim
    character(len=*), intent(in) :: name
    real(wp), intent(inout) :: data(:, :, :, :)
    integer :: b
    do b = 1, size(sim%blocks)
      call block_field_values(sim, name, b, data(:, :, :, b))
    end do
  end subroutine field_values

  !> field_values on block b.
  subroutine block_field_values(sim, name, b, data)
    type(sim_t), intent(in) :: sim
    character(len=*), intent(in) :: name
    integer, intent(in) :: b
    real(wp), intent(inout) :: data(:, :, :)
    integer :: j, k, n, p, off
    integer :: sel(sim%blocks(b)%n(1))
    logical :: isreal(sim%blocks(b)%n(1))
    real(wp), dimension(sim%blocks(b)%n(1)) :: rho, u, v, w, pr, e, aux
    n = sim%blocks(b)%n(1)
    associate (q => sim%blocks(b)%q)
      do k = 1, sim%blocks(b)%n(3)
        do j = 1, sim%blocks(b)%n(2)
          call phase_select(sim, q(1:n, j, k, :), sel, isreal)
          do p = 1, sim%ph%nphase
            if (.not. any(sel == p)) cycle
            off = sim%ph%lo(p) - 1
            associate (qp => q(1:n, j, k, off + 1:off + sim%ph%nflow))
              call primitive_row(sim%ph%eos(p), n, qp(:, i_rho), qp(:, i_mx), qp(:, i_my), &
                qp(:, i_mz), qp(:, i_en), rho, u, v, w, pr, e)
              select case (trim(name))
              case ('rho')
                aux = rho
              case ('u')
                aux = u
              case ('v')
                aux = v
              case ('w')
                aux = w
              case ('p')
                aux = pr
              case ('e')
                aux = e
              case ('T')
                if (sim%ph%strong(p)) then
                  call solid_temperature(sim%ph%eos(p), sim%ph%st(p), n, rho, e, qp, aux)
                else
                  call eos_temperature(sim%ph%eos(p), n, rho, e, aux)
                end if
              case ('c')
                call eos_sound_speed2(sim%ph%eos(p), n, rho, pr, aux)
                aux = sqrt(max(aux, 0.0_wp))
              case ('mach')
                call eos_sound_speed2(sim%ph%eos(p), n, rho, pr, aux)
                aux = sqrt(u**2 + v**2 + w**2) / sqrt(max(aux, tiny(1.0_wp)))
              case ('sxx', 'syy', 'szz', 'sxy', 'syz', 'sxz', 'eps_p', 'seq')
                aux = solid_field(name, qp, rho)
              case ('phase')
                aux = real(p, wp)
              case ('lambda')
                aux = 0.0_wp
                if (sim%ph%has_reaction) aux = qp(:, sim%ph%i_lambda) / rho
              case default
                aux = 0.0_wp
              end select
            end associate
            where (sel == p) data(1:n, j, k) = aux
          end do
        end do
      end do
    end associate
  end subroutine block_field_values

  !> A strength field of one row (zero when the state carries no stress): a deviatoric
  !> component, the effective plastic strain, or the von Mises stress sqrt(3 J2).
  function solid_field(name, qrow, rho) result(aux)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: qrow(:, :), rho(:)
    real(wp) :: aux(size(rho))
    character(len=*), parameter :: names(7) = [character(len=5) :: 'sxx', 'syy', 'szz', &
      'sxy', 'syz', 'sxz', 'eps_p']
    integer, parameter :: var(7) = [i_sxx, i_syy, i_szz, i_sxy, i_syz, i_sxz, i_epsp]
    integer :: k
    aux = 0.0_wp
    if (size(qrow, 2) < i_epsp) return
    k = findloc(names, name, 1)
    if (k > 0) then
      aux = qrow(:, var(k)) / rho
    else
      aux = sqrt(1.5_wp * (qrow(:, i_sxx)**2 + qrow(:, i_syy)**2 + qrow(:, i_szz)**2 &
        + 2.0_wp * (qrow(:, i_sxy)**2 + qrow(:, i_syz)**2 + qrow(:, i_sxz)**2))) / rho
    end if
  end function solid_field

  !> Columns of history.csv: totals over the real cells, maxima, fallback counters, and for
  !> each body of the flowing material its mass, volume and bounding box (from its level set).
  function history_columns(sim) result(cols)
    type(sim_t), intent(in) :: sim
    character(len=name_len), allocatable :: cols(:)
    character(len=4), parameter :: item(8) = [character(len=4) :: 'mass', 'vol', 'xmin', &
      'xmax', 'ymin', 'ymax', 'zmin', 'zmax']
    character(len=*), parameter :: cut_item(12) = [character(len=16) :: 'mass', 'energy', &
      'volume', 'in_mass', 'in_energy', 'stranded_mass', 'stranded_energy', 'content_volume', &
      'closing_cells', 'closing_heat', 'held_cells', 'excess_max']
    integer :: l, k, c
    character(len=16) :: pre
    cols = [character(len=name_len) :: 'step', 'time', 'dt', 'mass', 'mom_x', 'mom_y', &
      'mom_z', 'kinetic', 'internal', 'total_energy', 'max_p', 'max_T', 'max_eps_p', &
      'fallback_faces', 'first_order_steps', 'first_order_cells']
    if (sim%fix%on) cols = [character(len=name_len) :: cols, 'solid_mass', 'solid_energy', &
      'fixed_mass', 'fixed_energy', 'target_mass', 'target_energy']
    ! the cut-cell phase's budget (m_gfm_cut): content, what came in through the sides,
    ! what found no cell, the volume its level set encloses and the volume its content
    ! fills at the density of its states (their difference is the drift, theory.md 7c)
    ! (one set per cut phase: cut_ for the first, cut<k>_ for cut phase k after it)
    if (sim%cut(1)%on) then
      do c = 1, size(sim%cut)
        pre = 'cut'
        if (c > 1) pre = 'cut' // int_text(c)
        cols = [character(len=name_len) :: cols, (trim(pre) // '_' // trim(cut_item(k)), &
          k = 1, size(cut_item))]
        ! (with contacts: the energy in through them, so far)
        if (size(sim%cut) > 1) cols = [character(len=name_len) :: cols, &
          trim(pre) // '_exchange_energy']
      end do
    end if
    ! the mass burnt, sum rho lambda V over the real cells (reaction, m_reaction)
    if (sim%ph%has_reaction) cols = [character(len=name_len) :: cols, 'burnt_mass']
    do l = 1, sim%ls%n
      if (sim%ls%kind(l) /= ls_material) cycle
      cols = [character(len=name_len) :: cols, &
        (trim(sim%ls%name(l)) // '_' // trim(item(k)), k = 1, 8)]
    end do
    cols = [character(len=name_len) :: cols, hot_columns(sim%hot)]
  end function history_columns

  !> The history row after 'step': totals over the real cells (volume-weighted; 2 pi r in
  !> axisymmetry), maxima, the bodies' columns and the hot spots' (m_hotspot, whose run
  !> peaks it updates). max_T leaves out a gas without cv (no temperature); 0 when no phase
  !> has one.
  function history_values(sim) result(v)
    type(sim_t), intent(inout) :: sim
    real(wp), allocatable :: v(:)
    real(wp) :: tot(9), pmax, tmax, epmax, cut_tot(8), x
    real(wp), allocatable :: sums(:), xmax(:)
    integer :: b, ph, nsum, nc, c, r
    real(wp), allocatable :: body(:, :), part(:, :)
    logical :: has_t(sim%ph%nphase)
    do ph = 1, sim%ph%nphase
      has_t(ph) = is_set(sim%cfg%materials(material_index(sim%cfg, sim%ph%material(ph)))%cv)
    end do
    pmax = -huge(1.0_wp)
    tmax = -huge(1.0_wp)
    epmax = 0.0_wp
    ! block by block, then over the block ids: the same sums however the blocks are owned
    ! (rows: the totals, 4 for each cut phase (at least one set), the mass burnt)
    nc = size(sim%cut)
    r = 8 + 4 * nc
    nsum = merge(r, r - 1, sim%ph%has_reaction)
    allocate(part(nsum, size(sim%blocks)), xmax(nc))
    part = 0.0_wp
    call hot_row_start(sim%hot)
    xmax = 0.0_wp
    do b = 1, size(sim%blocks)
      tot = 0.0_wp
      call block_totals(sim, b, has_t, tot, pmax, tmax, epmax, sim%hot)
      part(1:7, b) = tot(1:7)
      do c = 1, nc
        if (.not. sim%cut(c)%on) cycle
        call cut_content(sim%cut(c), b, sim%blocks(b), sim%ph%lo(sim%cut(c)%p), &
          part(4 + 4 * c:7 + 4 * c, b), x)
        xmax(c) = max(xmax(c), x)
      end do
      if (sim%ph%has_reaction) part(r, b) = tot(9)
    end do
    sums = comm_sum_by_key(part, [(sim%blocks(b)%id, b = 1, size(sim%blocks))], &
      sim%lay%nblocks)
    tot(1:7) = sums(1:7)
    tot(8) = real(sim%diag%fallback_step, wp)
    tmax = comm_max(tmax)
    if (.not. any(has_t)) tmax = 0.0_wp
    v = [sim%clk%time, sim%clk%dt, tot(1:7), comm_max(pmax), tmax, comm_max(epmax), tot(8), &
      real(sim%diag%first_order_steps, wp), real(comm_sum(sim%diag%cells_low), wp)]
    if (sim%fix%on) v = [v, sim%fix%measure, sum(sim%fix%taken, dim=2), sum(sim%fix%content, dim=2)]
    do c = 1, nc
      if (.not. sim%cut(c)%on) cycle
      cut_tot(4:5) = sim%cut(c)%crossed
      cut_tot(6:7) = sim%cut(c)%stranded
      cut_tot(1:3) = sums(4 + 4 * c:6 + 4 * c)
      cut_tot(8) = sums(7 + 4 * c)
      v = [v, cut_tot, sim%cut(c)%closing, sim%cut(c)%held, comm_max(xmax(c))]
      if (nc > 1) v = [v, sim%cut(c)%exchanged]
    end do
    if (sim%ph%has_reaction) v = [v, sums(r)]
    if (sim%ls%n > 0) then
      body = body_measures(sim)
      v = [v, reshape(body, [size(body)])]
    end if
    v = [v, hot_row(sim%hot, sim%clk%time, tmax, tot(6), tot(5), void_volumes(sim), &
      sim%lay%cells)]
  end function history_values

  !> The totals and maxima of history_values over block b, added in cell order.
  subroutine block_totals(sim, b, has_t, tot, pmax, tmax, epmax, hot)
    type(sim_t), intent(in) :: sim
    integer, intent(in) :: b
    logical, intent(in) :: has_t(:)   !< phases with a temperature (max_T)
    real(wp), intent(inout) :: tot(9), pmax, tmax, epmax
    type(hot_t), intent(inout) :: hot   !< its cells' temperatures go to the hot spots
    real(wp), dimension(sim%blocks(b)%n(1)) :: rho, u, vv, w, p, e, temp, dv, msk
    integer :: sel(sim%blocks(b)%n(1))
    logical :: isreal(sim%blocks(b)%n(1))
    integer :: i, j, k, n, ph, o
    n = sim%blocks(b)%n(1)
    associate (q => sim%blocks(b)%q, off => sim%blocks(b)%offset)
      dv = [(cell_volume(sim%lay, off, i), i = 1, n)]
      if (hot%on) call hot_block(hot, sim%blocks(b)%id, cell_centre(sim%lay, off, 1, 1, 1), &
        cell_centre(sim%lay, off, n, sim%blocks(b)%n(2), sim%blocks(b)%n(3)))
      do k = 1, sim%blocks(b)%n(3)
        do j = 1, sim%blocks(b)%n(2)
          call phase_select(sim, q(1:n, j, k, :), sel, isreal)
          do ph = 1, sim%ph%nphase
            msk = merge(1.0_wp, 0.0_wp, isreal .and. sel == ph)
            if (.not. any(msk > 0.0_wp)) cycle
            o = sim%ph%lo(ph) - 1
            associate (qp => q(1:n, j, k, o + 1:o + sim%ph%nflow))
              call primitive_row(sim%ph%eos(ph), n, qp(:, i_rho), qp(:, i_mx), qp(:, i_my), &
                qp(:, i_mz), qp(:, i_en), rho, u, vv, w, p, e)
              if (sim%ph%strong(ph)) then
                call solid_temperature(sim%ph%eos(ph), sim%ph%st(ph), n, rho, e, qp, temp)
              else
                call eos_temperature(sim%ph%eos(ph), n, rho, e, temp)
              end if
              tot(1) = tot(1) + sum(msk * dv * rho)
              tot(2) = tot(2) + sum(msk * dv * qp(:, i_mx))
              tot(3) = tot(3) + sum(msk * dv * qp(:, i_my))
              tot(4) = tot(4) + sum(msk * dv * qp(:, i_mz))
              tot(5) = tot(5) + sum(msk * dv * 0.5_wp * rho * (u**2 + vv**2 + w**2))
              tot(6) = tot(6) + sum(msk * dv * rho * e)
              tot(7) = tot(7) + sum(msk * dv * qp(:, i_en))
              if (sim%ph%has_reaction) tot(9) = tot(9) + sum(msk * dv * qp(:, sim%ph%i_lambda))
              pmax = max(pmax, maxval(p, msk > 0.0_wp))
              if (has_t(ph)) tmax = max(tmax, maxval(temp, msk > 0.0_wp))
              if (has_t(ph) .and. hot%on) then
                do i = 1, n
                  if (.not. msk(i) > 0.0_wp .or. .not. hot_wants(hot, temp(i))) cycle
                  call hot_cell(hot, global_index(i, j, k), cell_centre(sim%lay, off, i, j, k), &
                    dv(i), rho(i), temp(i))
                end do
              end if
              if (sim%ph%strong(ph)) epmax = max(epmax, &
                maxval(qp(:, i_epsp) / rho, msk > 0.0_wp))
            end associate
          end do
        end do
      end do
    end associate

  contains

    !> the 0-based index of cell (i, j, k) of the block in the whole grid
    integer(i8) function global_index(i0, j0, k0) result(g)
      integer, intent(in) :: i0, j0, k0
      g = int(sim%blocks(b)%offset(1) + i0 - 1, i8) + int(sim%lay%cells(1), i8) &
        * (int(sim%blocks(b)%offset(2) + j0 - 1, i8) + int(sim%lay%cells(2), i8) &
        * int(sim%blocks(b)%offset(3) + k0 - 1, i8))
    end function global_index
  end subroutine block_totals

  !> The volume of each void body of the hot-spot diagnostics (its level set negative
  !> inside): sum f V with the cell's share f = 1/2 - phi / h, clipped to [0, 1], in one pass
  !> over the cells and one sum over the block ids.
  function void_volumes(sim) result(vol)
    type(sim_t), intent(in) :: sim
    real(wp) :: vol(size(sim%hot%void))
    real(wp) :: h, part(size(sim%hot%void), size(sim%blocks)), dv, x(3)
    integer :: b, i, j, k, v, n(3)
    integer, allocatable :: every(:)
    logical :: shared, mine(size(sim%hot%void))
    vol = 0.0_wp
    if (size(vol) == 0) return
    h = maxval(sim%lay%dx(1:sim%lay%ndim))
    part = 0.0_wp
    every = [(v, v = 1, size(vol))]
    ! (voids sharing a level set, the spheres of one body: each cell counts for the nearest)
    shared = .false.
    do v = 2, size(vol)
      if (any(sim%hot%void(1:v - 1)%l == sim%hot%void(v)%l)) shared = .true.
    end do
    do b = 1, size(sim%blocks)
      n = sim%blocks(b)%n
      do i = 1, n(1)
        dv = cell_volume(sim%lay, sim%blocks(b)%offset, i)
        if (.not. shared) then
          do v = 1, size(vol)
            part(v, b) = part(v, b) + dv * sum(min(1.0_wp, max(0.0_wp, 0.5_wp &
              - sim%blocks(b)%q(i, 1:n(2), 1:n(3), sim%ph%ils + sim%hot%void(v)%l) / h)))
          end do
          cycle
        end if
        do k = 1, n(3)
          do j = 1, n(2)
            x = cell_centre(sim%lay, sim%blocks(b)%offset, i, j, k)
            mine = hot_nearest(sim%hot, x, every)
            do v = 1, size(vol)
              if (mine(v)) part(v, b) = part(v, b) + dv * min(1.0_wp, max(0.0_wp, 0.5_wp &
                - sim%blocks(b)%q(i, j, k, sim%ph%ils + sim%hot%void(v)%l) / h))
            end do
          end do
        end do
      end do
    end do
    vol = comm_sum_by_key(part, [(sim%blocks(b)%id, b = 1, size(sim%blocks))], sim%lay%nblocks)
  end function void_volumes

  !> The phase of each cell of a row (the one whose composite level set is least there) and
  !> whether the cell is real for it (in its region).
  subroutine phase_select(sim, qrow, sel, isreal, least)
    type(sim_t), intent(in) :: sim
    real(wp), intent(in) :: qrow(:, :)
    integer, intent(out) :: sel(:)
    logical, intent(out) :: isreal(:)
    real(wp), intent(out), optional :: least(:)   !< the composite level set of that phase
    real(wp) :: bigphi(size(qrow, 1), 1, 1), best(size(qrow, 1))
    real(wp) :: phi(size(qrow, 1), 1, 1, sim%ls%n)
    integer :: owner(size(qrow, 1), 1, 1), p, nr
    sel = 1
    isreal = .true.
    if (present(least)) least = -huge(1.0_wp)
    if (sim%ls%n == 0) return
    nr = size(qrow, 1)
    best = huge(1.0_wp)
    phi = reshape(qrow(:, sim%ph%ils + 1:sim%ph%nvar), [nr, 1, 1, sim%ls%n])
    do p = 1, sim%ph%nphase
      call ls_region(sim%ls, p, [1, 1, 1], [nr, 1, 1], phi, bigphi, owner)
      where (bigphi(:, 1, 1) < best)
        sel = p
        best = bigphi(:, 1, 1)
      end where
    end do
    isreal = best < 0.0_wp
    if (present(least)) least = best
  end subroutine phase_select

  !> Mass and volume of the body of each material level set (in their order), and its
  !> bounding box. A cell counts with the
  !> fraction f = min(1, max(0, 1/2 - Phi / h)) of its volume (Phi the composite level set of
  !> the body's phase, h the largest cell size; 2 pi r weighted in axisymmetry), so that the
  !> measures move smoothly with the surface rather than by whole rows of cells; the mass
  !> takes the phase's density there (a ghost value in the outer half cell). The box edges
  !> are the zero crossings of phi between neighbouring cells (linear interpolation). All
  !> bodies in one pass over the rows: a row's phases are found once for all of them.
  function body_measures(sim) result(m)
    type(sim_t), intent(in) :: sim
    real(wp), allocatable :: m(:, :)
    real(wp) :: x(3), dv, t, edge, h, f
    integer :: b, i, j, k, d, c(3), iv, o, n(3), l, nb, ib
    integer, allocatable :: ls_of(:)   !< the material level sets, in order
    integer, allocatable :: sel(:)
    logical, allocatable :: isreal(:)
    real(wp), allocatable :: least(:), part(:, :, :), lo(:, :), hi(:, :)
    h = maxval(sim%lay%dx(1:sim%lay%ndim))
    ls_of = pack([(l, l = 1, sim%ls%n)], sim%ls%kind == ls_material)
    nb = size(ls_of)
    allocate(m(8, nb), part(2, size(sim%blocks), nb), lo(3, nb), hi(3, nb))
    if (nb == 0) return
    lo = huge(1.0_wp)
    hi = -huge(1.0_wp)
    part = 0.0_wp
    do b = 1, size(sim%blocks)
      n = sim%blocks(b)%n
      if (allocated(sel)) deallocate(sel, isreal, least)
      allocate(sel(n(1)), isreal(n(1)), least(n(1)))
      associate (q => sim%blocks(b)%q, off => sim%blocks(b)%offset)
        do k = 1, n(3)
          do j = 1, n(2)
            if (.not. any(q(1:n(1), j, k, sim%ph%ils + ls_of(1:nb)) < 0.5_wp * h)) cycle
            call phase_select(sim, q(1:n(1), j, k, :), sel, isreal, least)
            do ib = 1, nb
              l = ls_of(ib)
              iv = sim%ph%ils + l
              o = sim%ph%lo(sim%ls%phase(l)) - 1
              do i = 1, n(1)
                if (.not. q(i, j, k, iv) < 0.5_wp * h .or. sel(i) /= sim%ls%phase(l)) cycle
                x = cell_centre(sim%lay, off, i, j, k)
                dv = cell_volume(sim%lay, off, i)
                f = min(1.0_wp, max(0.0_wp, 0.5_wp - least(i) / h))
                part(2, b, ib) = part(2, b, ib) + f * dv
                part(1, b, ib) = part(1, b, ib) + f * dv * q(i, j, k, o + i_rho)
                if (.not. q(i, j, k, iv) < 0.0_wp) cycle
                do d = 1, sim%lay%ndim
                  lo(d, ib) = min(lo(d, ib), x(d))
                  hi(d, ib) = max(hi(d, ib), x(d))
                  c = [i, j, k]
                  c(d) = c(d) + 1
                  t = q(c(1), c(2), c(3), iv)
                  if (t >= 0.0_wp) then
                    edge = x(d) + sim%lay%dx(d) * q(i, j, k, iv) / (q(i, j, k, iv) - t)
                    hi(d, ib) = max(hi(d, ib), edge)
                  end if
                  c(d) = c(d) - 2
                  t = q(c(1), c(2), c(3), iv)
                  if (t >= 0.0_wp) then
                    edge = x(d) - sim%lay%dx(d) * q(i, j, k, iv) / (q(i, j, k, iv) - t)
                    lo(d, ib) = min(lo(d, ib), edge)
                  end if
                end do
              end do
            end do
          end do
        end do
      end associate
    end do
    do ib = 1, nb
      ! over the block ids: the same sums however the blocks are owned
      m(1:2, ib) = comm_sum_by_key(part(:, :, ib), [(sim%blocks(b)%id, b = 1, &
        size(sim%blocks))], sim%lay%nblocks)
      do d = 1, 3
        m(1 + 2 * d, ib) = -comm_max(-lo(d, ib))
        m(2 + 2 * d, ib) = comm_max(hi(d, ib))
        if (d > sim%lay%ndim) m(1 + 2 * d:2 + 2 * d, ib) = 0.0_wp
      end do
    end do
  end function body_measures

  !> Check out_dir, create it, and write the resolved deck there (out_dir/deck.nml, by
  !> m_deck's deck_write_resolved). Collective. A refusal is a deck error of &run out_dir. Results
  !> already in out_dir stop the run unless overwrite is set or the
  !> run restarts from a checkpoint in that same folder (a restart continues a run; that the
  !> checkpoint is one, output_restart_check of m_checkpoint has made sure before).
  subroutine output_prepare(cfg)
    type(config_t), intent(in) :: cfg
    character(len=:), allocatable :: dir
    character(len=2 * path_len + line_len) :: msg
    logical :: ok, continuing
    integer :: ios, stat, cmd_stat
    ok = .true.
    msg = ''
    if (comm_is_root()) then
      dir = normal_path(cfg%out_dir)
      continuing = len_trim(cfg%restart) > 0 .and. dir_name(cfg%restart) == dir
      if (.not. continuing .and. .not. cfg%overwrite) then
        if (holds_results(dir)) call refuse("'" // trim(cfg%out_dir) &
          // "' already holds results (set overwrite = .true. or choose another out_dir)", '')
      else if (.not. continuing) then
        ! a fresh run replaces the results it overwrites: an old plot file with a later step
        ! number must not pass for this run's last one
        call execute_command_line('cd ' // shell_word(dir) // ' 2>/dev/null && rm -f ' &
          // 'run.log history.csv plot_*.h5 plot_*.xmf chk_*.h5', exitstat=stat, cmdstat=cmd_stat)
      end if
      if (ok) then
        call execute_command_line('mkdir -p ' // shell_word(dir), exitstat=stat, &
          cmdstat=cmd_stat)
        if (stat /= 0 .or. cmd_stat /= 0) call refuse("cannot create '" // dir &
          // "' (check the path and permissions)", "'out/sod'")
      end if
      if (ok) then
        call deck_write_resolved(cfg, dir // '/deck.nml', ios)
        if (ios /= 0) call refuse("cannot write '" // dir // "/deck.nml' (check permissions)", &
          "'out/sod'")
      end if
    end if
    call stop_collective(msg, ok)

  contains

    !> the error of out_dir (the first: what would follow it is not tried)
    subroutine refuse(why, typical)
      character(len=*), intent(in) :: why, typical
      ok = .false.
      msg = error_line(base_name(cfg%deck_file), '&run out_dir', why, typical)
    end subroutine refuse

  end subroutine output_prepare

  !> Whether a folder holds results of a run: run.log, history.csv, plot_*.h5, chk_*.h5.
  logical function holds_results(dir)
    character(len=*), intent(in) :: dir
    integer :: stat, cmd_stat
    call execute_command_line('ls -1A ' // shell_word(dir) // ' 2>/dev/null | grep -Eq ' &
      // "'^(run\.log|history\.csv|(plot_.*|chk_.*)\.h5)$'", exitstat=stat, cmdstat=cmd_stat)
    holds_results = (cmd_stat == 0 .and. stat == 0)
  end function holds_results

  !> t as one word of a shell command: in single quotes, an inner quote as '\''.
  function shell_word(t) result(r)
    character(len=*), intent(in) :: t
    character(len=:), allocatable :: r
    r = "'" // replaced(trim(t), "'", "'\''") // "'"
  end function shell_word

end module m_output
