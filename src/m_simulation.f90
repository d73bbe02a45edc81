!> The simulation in typed parts (sim_t): the resolved deck, the block layout, this rank's
!> blocks, the halo plan and boundary conditions, the clock and output schedule, the phases,
!> the scheme choices, the level-set bodies, the ghost-fluid and conservation-fix states,
!> the step's counters, the work space, the memory estimate and the blocks' measured work
!> (m_balance; m_rebalance moves blocks between ranks when it drifts). sim_setup turns a deck into a
!> ready-to-run simulation: layout, rigid-obstacle blocks, the memory estimate (m_memory; a deck
!> that
!> does not fit the node is refused before anything is allocated), METIS partition,
!> allocation and the initial state painted from the bodies (or read from a checkpoint by
!> m_output).
module m_simulation
  use m_kinds, only: wp, name_len
  use m_config, only: config_t, material_t, material_index, is_set
  use m_layout, only: layout_t, layout_init, block_offset, block_extent, n_halo
  use m_blocks, only: block_t, blocks_allocate
  use m_halo, only: halo_plan_t, halo_plan_build
  use m_partition, only: partition_blocks
  use m_balance, only: balance_t, balance_start
  use m_boundary, only: bc_kind_t, bc_from_name
  use m_eos, only: eos_t, eos_from_material, eos_energy, eos_prepare, eos_temperature
  use m_euler, only: euler_work_t, euler_work_init, numerics_t
  use m_runge_kutta, only: euler_max_rate
  use m_phases, only: phases_t
  use m_fallback, only: counters_t
  use m_gfm_conserve, only: fix_t, fix_setup
  use m_gfm_cut, only: cut_t
  use m_gfm_cut_setup, only: cut_setup
  use m_reconstruct, only: scheme_from_name, stencil_reach
  use m_characteristic, only: variables_from_name
  use m_flux, only: flux_from_name, scalar_flux_from_name
  use m_scene, only: inside_body, cell_centre, body_distance, rigid_block_status, &
    scene_generate, made_t
  use m_levelset_bodies, only: ls_set_t, ls_material, ls_void, ls_rigid, ls_region
  use m_gfm, only: gf_t, gf_fit, probe_from_name
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, n_euler, n_solid
  use m_yield, only: strength_t, strength_from_material, strength_none
  use m_timers, only: timers_t
  use m_memory, only: memory_t, memory_estimate, memory_check
  use m_comm, only: comm_rank, comm_any, comm_max, comm_backend_name
  use m_errors, only: stop_collective, error_line
  use m_text, only: base_name, int_text
  use m_hotspot, only: hot_t, hot_start
  use m_reaction, only: reaction_from_name, reaction_none
  use m_conduction, only: conduction_rate
  implicit none
  private
  public :: sim_t, sim_setup, sim_paint_initial_state, sim_block_work, sim_rate, sim_plan

  !> Depth of the ghost band in cells: the reach (3) of the ENO3 and WENO5 stencils of a real
  !> cell next to the surface, and a half cell for oblique surfaces.
  real(wp), parameter :: ghost_depth = 3.5_wp

  !> The clock and the output schedule.
  type :: clock_t
    real(wp) :: time = 0.0_wp, dt = 0.0_wp, dt_first = 0.0_wp
    integer :: step = 0
    integer :: restart_step = 0
    integer :: plot_count = 0          !< plot files written so far
    integer :: last_plot_step = -1
    real(wp) :: next_plot_time = 0.0_wp
    real(wp) :: wall_start = 0.0_wp    !< wall clock at the start of the run
  end type clock_t

  !> Work space of one block that the blocks share (shaped by sim_block_work).
  type :: work_t
    type(euler_work_t) :: euler
    real(wp), allocatable :: qsave(:, :, :, :)   !< a block's stage input (interior)
    logical, allocatable :: trouble(:, :, :)     !< its cells left inadmissible
  end type work_t

  !> The simulation in parts; each routine takes the parts it uses.
  type :: sim_t
    type(config_t) :: cfg              !< the resolved deck
    type(layout_t) :: lay              !< the grid of blocks
    type(block_t), allocatable :: blocks(:)   !< this rank's blocks
    type(halo_plan_t) :: plan
    !> with flow_faces, the faces-only plan of the flow exchange after the ghost fill
    type(halo_plan_t) :: plan_flow
    logical :: flow_faces = .false.
    type(bc_kind_t) :: bc
    type(clock_t) :: clk
    type(phases_t) :: ph               !< the phases and the state layout (m_phases)
    type(numerics_t) :: num            !< scheme choices (m_euler)
    type(ls_set_t) :: ls               !< level-set bodies (m_levelset_bodies)
    type(made_t), allocatable :: made(:)   !< what the generators made of each body (m_scene)
    type(gf_t) :: gf                   !< the ghost-fluid state (m_gfm)
    type(fix_t) :: fix                 !< the conservation fix (m_gfm_conserve)
    type(cut_t), allocatable :: cut(:)  !< cut-cell update, one per cut phase (m_gfm_cut_setup)
    type(counters_t) :: diag           !< what the step had to do, and its cost (m_fallback)
    type(work_t) :: wk
    type(timers_t) :: timers
    type(memory_t) :: mem
    type(balance_t) :: bal             !< the blocks' measured work, checks, migrations
    type(hot_t) :: hot                 !< hot-spot diagnostics (m_hotspot)
    !> &run overlap where it applies: a deck without level sets, whose flow ghosts are its
    !> only ghost step (m_step)
    logical :: overlap = .false.
  end type sim_t

contains

  !> (The generated shapes of the bodies are made here, into sim%made: m_scene.)
  subroutine sim_setup(cfg, sim)
    type(config_t), intent(in) :: cfg
    type(sim_t), intent(inout) :: sim
    logical :: periodic(3)
    integer :: d, p
    integer, allocatable :: work(:)
    type(material_t) :: mat
    call scene_generate(cfg%bodies(1:cfg%n_bodies), cfg%ndim, cfg%band * maxval((cfg%hi(1: &
      cfg%ndim) - cfg%lo(1:cfg%ndim)) / cfg%cells(1:cfg%ndim)), base_name(cfg%deck_file), &
      sim%made)
    sim%cfg = cfg
    do d = 1, 3
      periodic(d) = trim(cfg%bc_lo(d)) == 'periodic'
      sim%bc%lo(d) = bc_from_name(cfg%bc_lo(d))
      sim%bc%hi(d) = bc_from_name(cfg%bc_hi(d))
    end do
    sim%bc%velocity = cfg%bc_velocity
    sim%bc%rise_time = cfg%bc_rise_time
    call layout_init(sim%lay, cfg%ndim, cfg%cells, cfg%block, cfg%lo, cfg%hi, periodic, &
      trim(cfg%geometry) == 'axisymmetric')
    call level_set_bodies(cfg, sim)
    sim%ph%nphase = sim%ls%nphase
    allocate(sim%ph%eos(sim%ph%nphase), sim%ph%st(sim%ph%nphase), sim%ph%shear(sim%ph%nphase), &
      sim%ph%strong(sim%ph%nphase), sim%ph%rest(2, sim%ph%nphase), &
      sim%ph%conductivity(sim%ph%nphase), sim%ph%rt(sim%ph%nphase))
    sim%ph%strength_reason = ''
    do p = 1, sim%ph%nphase
      mat = cfg%materials(material_index(cfg, sim%ph%material(p)))
      sim%ph%st(p) = strength_from_material(mat)
      sim%ph%strong(p) = cfg%strength .and. sim%ph%st(p)%model /= strength_none
      sim%ph%shear(p) = 0.0_wp
      if (sim%ph%strong(p)) sim%ph%shear(p) = sim%ph%st(p)%g
      sim%ph%eos(p) = eos_from_material(mat)
      call eos_prepare(sim%ph%eos(p))
      sim%ph%rest(:, p) = [mat%rho0, mat%p0]
      sim%ph%conductivity(p) = 0.0_wp
      if (cfg%heat_conduction .and. is_set(mat%conductivity)) &
        sim%ph%conductivity(p) = mat%conductivity
      if (cfg%reaction) sim%ph%rt(p) = reaction_from_name(mat%reaction, mat%reaction_q)
      if (any(sim%ph%material(1:p-1) == sim%ph%material(p))) cycle
      if (len_trim(sim%ph%strength_reason) > 0) &
        sim%ph%strength_reason = trim(sim%ph%strength_reason) // '; '
      sim%ph%strength_reason = trim(sim%ph%strength_reason) // ' ' // trim(strength_text(p))
    end do
    sim%ph%strength_reason = adjustl(sim%ph%strength_reason)
    sim%ph%has_strength = any(sim%ph%strong)
    if (sim%ph%has_strength) sim%ph%nflow = n_solid
    call heat_effects()
    sim%ph%ils = sim%ph%nphase * sim%ph%nflow
    sim%ph%nvar = sim%ph%ils + sim%ls%n
    call memory_estimate(sim%lay, sim%ph%nvar, sim%ph%nflow, sim%ph%nphase, sim%ls%n, sim%mem)
    call memory_check(sim%mem, sim%cfg%deck_file)
    work = predicted_work(sim)
    call partition_blocks(sim%lay, work)
    call blocks_allocate(sim%lay, comm_rank(), sim%ph%nvar, sim%blocks)
    ! conserve = 'auto' or 'cut_cell': by the fluxes where m_gfm_cut applies (its exchanges
    ! take sim_plan's whole plan), else by the fix (below)
    call cut_setup(sim%cut, cfg%conserve, cfg%heat_conduction .or. cfg%reaction, &
      cfg%body_follow, sim%lay, sim%ph, sim%ls, sim%blocks)
    call sim_plan(sim)
    sim%bal%threshold = cfg%rebalance_threshold
    sim%bal%every = cfg%rebalance_every
    call balance_start(sim%bal, size(sim%blocks))
    call shape_work(sim, sim%lay)
    ! every block is awake without level sets
    allocate(sim%gf%dormant(size(sim%blocks)))
    sim%gf%dormant = .false.
    sim%overlap = cfg%overlap .and. sim%ls%n == 0
    if (sim%ls%n > 0) then
      sim%gf%scn%eos = sim%ph%eos
      sim%gf%scn%shear = sim%ph%shear
      sim%gf%scn%rest = sim%ph%rest
      sim%gf%scn%nflow = sim%ph%nflow
      sim%gf%scn%probe = probe_from_name(cfg%gfm_probe)
      sim%gf%scn%band = ghost_depth * maxval(sim%lay%dx(1:sim%lay%ndim))
      sim%gf%scn%contact = cfg%contact_kappa * maxval(sim%lay%dx(1:sim%lay%ndim))
      if (sim%cut(1)%on) then
        sim%bc%linear_levelsets = .true.
        call fix_setup(sim%fix, sim%ph, sim%ls, 'none', size(sim%blocks))
        sim%fix%reason = 'off: the cut-cell update conserves by its fluxes'
      else if (cfg%conserve == 'cut_cell' .or. cfg%conserve == 'auto') then
        call fix_setup(sim%fix, sim%ph, sim%ls, 'mass_energy', size(sim%blocks))
      else
        call fix_setup(sim%fix, sim%ph, sim%ls, cfg%conserve, size(sim%blocks))
      end if
    end if
    call hot_start(sim%hot, sim%cfg, sim%made, sim%ls, sim%ph%material, sim%lay%ndim, &
      sim%lay%nblocks)
    sim%num%scheme = scheme_from_name(cfg%scheme)
    sim%num%variables = variables_from_name(cfg%variables)
    sim%num%flux = flux_from_name(cfg%flux)
    sim%num%scalar_flux = scalar_flux_from_name(cfg%scalar_flux)
    sim%num%surface_llf = cfg%surface_flux == 'llf'

  contains

    !> Heat conduction and reaction (m_conduction, m_reaction): on as &physics resolved them;
    !> with reaction, rho lambda is appended to every phase's variables; and why, for run.log.
    subroutine heat_effects()
      sim%ph%has_conduction = any(sim%ph%conductivity > 0.0_wp)
      sim%ph%has_reaction = any(sim%ph%rt%model /= reaction_none)
      if (sim%ph%has_reaction) then
        sim%ph%nflow = sim%ph%nflow + 1
        sim%ph%i_lambda = sim%ph%nflow
      end if
      sim%ph%conduction_reason = 'off: no material in use has a conductivity'
      if (.not. cfg%heat_conduction .and. any(is_set(cfg%materials(1:cfg%n_materials) &
        %conductivity))) sim%ph%conduction_reason = 'off: &physics heat_conduction = .false.'
      if (sim%ph%has_conduction) sim%ph%conduction_reason = 'on: material' // &
        materials_with(sim%ph%conductivity > 0.0_wp) // ' has a conductivity'
      sim%ph%reaction_reason = 'off: no material in use has a reaction'
      if (.not. cfg%reaction .and. any(cfg%materials(1:cfg%n_materials)%reaction /= 'none' &
        .and. cfg%materials(1:cfg%n_materials)%reaction /= '')) &
        sim%ph%reaction_reason = 'off: &physics reaction = .false.'
      if (sim%ph%has_reaction) sim%ph%reaction_reason = 'on: material' // &
        materials_with(sim%ph%rt%model /= reaction_none) // ' reacts (rho lambda in the state)'
    end subroutine heat_effects

    !> the materials of the phases marked, each once
    function materials_with(mark) result(names)
      logical, intent(in) :: mark(:)
      character(len=:), allocatable :: names
      integer :: pp
      names = ''
      do pp = 1, size(mark)
        if (mark(pp) .and. .not. any(mark(1:pp-1) .and. &
          sim%ph%material(1:pp-1) == sim%ph%material(pp))) &
          names = names // ' ' // trim(sim%ph%material(pp))
      end do
    end function materials_with

    !> the run log's reason for strength of phase pp's material
    function strength_text(pp) result(t)
      integer, intent(in) :: pp
      character(len=128) :: t
      if (sim%ph%strong(pp)) then
        t = 'on: material ' // trim(mat%name) // ' has ' // trim(mat%strength_model)
      else if (sim%ph%st(pp)%model /= strength_none) then
        t = 'off: &physics strength = .false. (material ' // trim(mat%name) // ' has ' // &
          trim(mat%strength_model) // ')'
      else
        t = 'off: material ' // trim(mat%name) // ' has no strength'
      end if
    end function strength_text

  end subroutine sim_setup

  !> Shape the work arrays that the blocks share (flux and ghost-fill scratch, the stage copy,
  !> the trouble mask, the level-set velocity and rates) for block b before it is computed:
  !> the last block along a direction may have another extent (m_layout), and every array a
  !> kernel sees has the extent of the block it works on. Reallocates only when the extent
  !> differs from that of the block they were last shaped for.
  subroutine sim_block_work(sim, b)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b
    if (sim%ls%n > 0) call gf_fit(sim%gf, sim%blocks(b)%lay, sim%ph%nflow, sim%ph%nphase)
    if (all(shape(sim%wk%trouble) == sim%blocks(b)%n)) return
    call shape_work(sim, sim%blocks(b)%lay)
  end subroutine sim_block_work

  !> The shared work arrays for a block of layout (or view) bl.
  subroutine shape_work(sim, bl)
    type(sim_t), intent(inout) :: sim
    type(layout_t), intent(in) :: bl
    integer :: n(3)
    n = bl%bsize
    if (allocated(sim%wk%qsave)) deallocate(sim%wk%qsave, sim%wk%trouble)
    call euler_work_init(bl, sim%ph%nflow, sim%wk%euler)
    allocate(sim%wk%qsave(n(1), n(2), n(3), sim%ph%nvar), sim%wk%trouble(n(1), n(2), n(3)))
    if (sim%ls%n > 0) call gf_fit(sim%gf, bl, sim%ph%nflow, sim%ph%nphase)
  end subroutine shape_work

  !> Which bodies carry level sets, and the phases (manual/interfaces.md section 1): the base
  !> material when it is not void (phase 1), then each material body. Every void and rigid
  !> body, and every body of a material other than the base, gets a level set, except a
  !> resting rigid body made of whole blocks (a step, a wall segment), whose blocks are
  !> switched off so that their faces are exact walls; blocks that lie deep inside a rigid
  !> body (farther than the band and the halo from its surface) are not computed at all.
  subroutine level_set_bodies(cfg, sim)
    type(config_t), intent(in) :: cfg
    type(sim_t), intent(inout) :: sim
    integer :: b, n, id, i, j, k, off(3), np, ext(3), c
    real(wp) :: deep, dmax
    logical, allocatable :: whole(:)
    call stop_collective(error_line(trim(base_name(cfg%deck_file)), '&domain base_material', &
      'with a void base some &body must be of a material', ''), cfg%base_material /= 'void' .or. &
      any([(cfg%bodies(b)%material /= 'void' .and. cfg%bodies(b)%material /= 'rigid', &
      b = 1, cfg%n_bodies)]))
    sim%ls%base_flows = cfg%base_material /= 'void'
    allocate(whole(cfg%n_bodies))
    whole = .false.
    do b = 1, cfg%n_bodies
      associate (body => cfg%bodies(b))
        if (.not. own_level_set(b)) cycle
        ! a resting rigid body made of whole blocks: those blocks are switched off and their
        ! faces are exact walls of the neighbouring blocks (m_boundary); no level set
        if (body%material == 'rigid' .and. .not. any(abs(body%velocity) > 0.0_wp)) &
          whole(b) = all([(rigid_block_status(sim%lay, id, body, sim%made(b)) /= 1, id = 1, &
          sim%lay%nblocks)])
        if (.not. whole(b)) cycle
        do id = 1, sim%lay%nblocks
          if (rigid_block_status(sim%lay, id, body, sim%made(b)) == 2) &
            sim%lay%active(id) = .false.
        end do
      end associate
    end do
    ! a level set per body, but one per colour of a body of grains (m_scene_grains)
    n = sum([(merge(colours(b), 0, own_level_set(b) .and. .not. whole(b)), b = 1, &
      cfg%n_bodies)])
    sim%ls%n = n
    allocate(sim%ls%kind(n), sim%ls%body(n), sim%ls%name(n), sim%ls%velocity(3, n), &
      sim%ls%phase(n), sim%ls%colour(n))
    allocate(sim%ph%material(n + 1))
    np = 0
    if (sim%ls%base_flows) then
      np = 1
      sim%ph%material(1) = cfg%base_material
    end if
    n = 0
    do b = 1, cfg%n_bodies
      associate (body => cfg%bodies(b))
        if (.not. own_level_set(b) .or. whole(b)) cycle
        do c = 1, colours(b)
          n = n + 1
          sim%ls%body(n) = b
          sim%ls%colour(n) = merge(c, 0, body%shape == 'grains')
          sim%ls%name(n) = body%name
          if (body%shape == 'grains') sim%ls%name(n) = trim(body%name) // '.' // int_text(c)
          sim%ls%velocity(:, n) = body%velocity
          sim%ls%phase(n) = 0
          select case (trim(body%material))
          case ('void')
            sim%ls%kind(n) = ls_void
          case ('rigid')
            sim%ls%kind(n) = ls_rigid
          case default
            sim%ls%kind(n) = ls_material
            np = np + 1
            sim%ls%phase(n) = np
            sim%ph%material(np) = body%material
          end select
        end do
        if (sim%ls%kind(n) /= ls_rigid .or. any(abs(body%velocity) > 0.0_wp)) cycle
        ! blocks deep inside a resting rigid body are not computed
        deep = -(real(cfg%band + maxval(sim%lay%ng), wp) + 1.0_wp) &
          * maxval(sim%lay%dx(1:sim%lay%ndim))
        do id = 1, sim%lay%nblocks
          off = block_offset(sim%lay, id)
          ext = block_extent(sim%lay, id)
          dmax = -huge(1.0_wp)
          do k = 1, ext(3)
            do j = 1, ext(2)
              do i = 1, ext(1)
                dmax = max(dmax, body_distance(body, sim%made(b), sim%lay%ndim, &
                  cell_centre(sim%lay, off, i, j, k)))
              end do
            end do
          end do
          if (dmax < deep) sim%lay%active(id) = .false.
        end do
      end associate
    end do
    sim%ls%nphase = np
    sim%ph%material = sim%ph%material(1:np)

  contains

    !> the level sets of body ib: one, or one per colour of its grains
    integer function colours(ib)
      integer, intent(in) :: ib
      colours = 1
      if (cfg%bodies(ib)%shape == 'grains') colours = sim%made(ib)%grains%ncolour
    end function colours

    !> A body of the base material only sets the initial state; so does a void body in a
    !> void base, unless a material body comes before it in the deck, which it then carves
    !> (a hole in a plate).
    logical function own_level_set(ib)
      integer, intent(in) :: ib
      integer :: ia
      own_level_set = cfg%bodies(ib)%material /= cfg%base_material
      if (own_level_set .or. cfg%bodies(ib)%material /= 'void') return
      own_level_set = any([(cfg%bodies(ia)%material /= 'void' .and. &
        cfg%bodies(ia)%material /= 'rigid', ia = 1, ib - 1)])
    end function own_level_set

  end subroutine level_set_bodies

  !> Initial state: each phase at its reference state at rest where it is not computed; the
  !> base phase its material with the bodies of that material painted over it in deck
  !> order, a body's phase the body's own state. The level sets start as the bodies' signed
  !> distances, a later material body cut out of the earlier ones (phi_l = max(phi_l,
  !> -phi_m)); cells outside a phase's region hold its rest state (the first stage's ghost
  !> fill replaces it near the interfaces).
  subroutine sim_paint_initial_state(sim)
    type(sim_t), intent(inout) :: sim
    integer :: b, i, j, k, l, m
    real(wp) :: x(3), phi(1, 1, 1, sim%ls%n)
    real(wp), parameter :: two_pi = 8.0_wp * atan(1.0_wp)
    do b = 1, size(sim%blocks)
      associate (blk => sim%blocks(b))
        do k = 1, blk%n(3)
          do j = 1, blk%n(2)
            do i = 1, blk%n(1)
              x = cell_centre(sim%lay, blk%offset, i, j, k)
              do l = 1, sim%ls%n
                phi(1, 1, 1, l) = body_distance(sim%cfg%bodies(sim%ls%body(l)), &
                  sim%made(sim%ls%body(l)), sim%lay%ndim, x, sim%ls%colour(l))
                if (sim%ls%kind(l) /= ls_material) cycle
                do m = 1, l - 1
                  if (sim%ls%kind(m) == ls_material) &
                    phi(1, 1, 1, m) = max(phi(1, 1, 1, m), -phi(1, 1, 1, l))
                end do
              end do
              blk%q(i, j, k, sim%ph%ils + 1:sim%ph%nvar) = phi(1, 1, 1, :)
              call phase_states(blk%q(i, j, k, :), x, phi)
            end do
          end do
        end do
      end associate
    end do

  contains

    !> The state of every phase in the cell at x of level sets phi: its rest state, or the
    !> state of the last body that paints the phase and holds x, within the phase's region.
    subroutine phase_states(qc, x, phi)
      real(wp), intent(inout) :: qc(:)
      real(wp), intent(in) :: x(3), phi(1, 1, 1, sim%ls%n)
      integer :: p, nb, off, own(1, 1, 1)
      real(wp) :: rho, vel(3), pres, e(1), bigphi(1, 1, 1), rest(2), temp
      do p = 1, sim%ph%nphase
        rest = sim%ph%rest(:, p)
        rho = rest(1)
        pres = rest(2)
        vel = 0.0_wp
        temp = -1.0_wp
        do nb = 1, sim%cfg%n_bodies
          if (.not. paints(nb, p)) cycle
          associate (body => sim%cfg%bodies(nb))
            if (.not. inside_body(body, sim%made(nb), sim%lay%ndim, x)) cycle
            ! the exact cell average of the sinusoid, so that smooth data start at
            ! the order of the scheme rather than at second order
            rho = body%rho * (1.0_wp + body%amplitude &
              * sin(two_pi * dot_product(body%wavevector, x)) &
              * product(sinc(0.5_wp * two_pi * body%wavevector * sim%lay%dx)))
            pres = body%p
            temp = -1.0_wp
            if (is_set(body%T)) then
              ! a body given by its temperature: the perturbation is of T, at rho
              rho = body%rho
              temp = body%T * (1.0_wp + body%amplitude &
                * sin(two_pi * dot_product(body%wavevector, x)) &
                * product(sinc(0.5_wp * two_pi * body%wavevector * sim%lay%dx)))
            end if
            vel = body%velocity
          end associate
        end do
        if (sim%ls%n > 0) then
          call ls_region(sim%ls, p, [1, 1, 1], [1, 1, 1], phi, bigphi, own)
          if (bigphi(1, 1, 1) >= 0.0_wp) then
            rho = rest(1)
            pres = rest(2)
            vel = 0.0_wp
            temp = -1.0_wp
          end if
        end if
        if (temp > 0.0_wp) then
          ! T is linear in e at fixed rho with slope 1 / cv for every eos (eq. 2.11)
          call eos_temperature(sim%ph%eos(p), 1, [rho], [0.0_wp], e)
          e = sim%ph%eos(p)%cv * (temp - e)
        else
          call eos_energy(sim%ph%eos(p), 1, [rho], [pres], e)
        end if
        off = sim%ph%lo(p) - 1
        qc(off + 1:off + sim%ph%nflow) = 0.0_wp
        qc(off + i_rho) = rho
        qc(off + i_mx) = rho * vel(1)
        qc(off + i_my) = rho * vel(2)
        qc(off + i_mz) = rho * vel(3)
        qc(off + i_en) = rho * (e(1) + 0.5_wp * sum(vel**2))
      end do
    end subroutine phase_states

    !> body nb paints phase pp: a body of the base material paints the base phase; a
    !> material body with a level set paints its own phase
    logical function paints(nb, pp)
      integer, intent(in) :: nb, pp
      integer :: ll
      paints = sim%ls%base_flows .and. pp == 1 .and. &
        sim%cfg%bodies(nb)%material == sim%cfg%base_material
      do ll = 1, sim%ls%n
        if (sim%ls%body(ll) == nb .and. sim%ls%phase(ll) == pp) paints = .true.
      end do
    end function paints

  end subroutine sim_paint_initial_state

  elemental real(wp) function sinc(z)
    real(wp), intent(in) :: z
    sinc = 1.0_wp
    if (abs(z) > 1.0e-8_wp) sinc = sin(z) / z
  end function sinc

  !> The global signal rate (max over ranks) for the CFL step (dt = cfl / rate), and whether
  !> every cell of every rank is admissible.
  subroutine sim_rate(sim, rate, ok)
    type(sim_t), intent(inout) :: sim
    real(wp), intent(out) :: rate
    logical, intent(out) :: ok
    real(wp) :: r
    logical :: good, all_good
    integer :: b, p
    rate = 0.0_wp
    all_good = .true.
    do b = 1, size(sim%blocks)
      do p = 1, sim%ph%nphase
        call euler_max_rate(sim%blocks(b)%lay, sim%ph%eos(p), sim%ph%shear(p), &
          sim%blocks(b)%q(:, :, :, sim%ph%lo(p):sim%ph%hi(p)), r, good)
        rate = max(rate, r)
        all_good = all_good .and. good
        ! explicit conduction: dt = cfl / rate at most half its stable step, 1 / rate_c
        if (sim%ph%conductivity(p) > 0.0_wp) rate = max(rate, 2.0_wp * sim%cfg%cfl &
          * conduction_rate(sim%blocks(b)%lay, sim%ph%conductivity(p), sim%ph%eos(p)%cv, &
          sim%blocks(b)%q(:, :, :, sim%ph%lo(p) + i_rho - 1)))
      end do
    end do
    ok = .not. comm_any(.not. all_good)
    rate = comm_max(rate)
    if (.not. rate > 0.0_wp) rate = tiny(1.0_wp)
  end subroutine sim_rate

  !> The first partition's block weights (the measured work takes over at the balance
  !> checks, m_balance): a block's cells, or 1 for a block that starts dormant by m_gfm's
  !> rule (every cell of the padded block beyond the ghost band of every phase, on the
  !> bodies' level sets at t = 0), which the step does not compute.
  function predicted_work(sim) result(work)
    type(sim_t), intent(in) :: sim
    integer :: work(sim%lay%nblocks)
    real(wp), allocatable :: phi(:, :, :, :), bigphi(:, :, :)
    integer, allocatable :: owner(:, :, :)
    integer :: id, l, i, j, k, p, off(3), lo(3), hi(3)
    real(wp) :: band
    logical :: dormant
    band = ghost_depth * maxval(sim%lay%dx(1:sim%lay%ndim))
    lo = 1 - sim%lay%ng
    hi = sim%lay%bsize + sim%lay%ng
    if (sim%ls%n > 0) allocate(phi(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), sim%ls%n), &
      bigphi(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)), owner(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)))
    do id = 1, sim%lay%nblocks
      work(id) = product(block_extent(sim%lay, id))
      if (sim%ls%n == 0 .or. .not. sim%lay%active(id)) cycle
      off = block_offset(sim%lay, id)
      do l = 1, sim%ls%n
        do k = lo(3), hi(3)
          do j = lo(2), hi(2)
            do i = lo(1), hi(1)
              phi(i, j, k, l) = body_distance(sim%cfg%bodies(sim%ls%body(l)), &
                sim%made(sim%ls%body(l)), sim%lay%ndim, cell_centre(sim%lay, off, i, j, k), &
                sim%ls%colour(l))
            end do
          end do
        end do
      end do
      dormant = .true.
      do p = 1, sim%ls%nphase
        call ls_region(sim%ls, p, lo, hi, phi, bigphi, owner)
        dormant = dormant .and. all(bigphi > band)
      end do
      if (dormant) work(id) = 1
    end do
  end function predicted_work

  !> The halo plan of this rank's blocks (m_halo), built again after a migration. A scene
  !> without level sets (whose derivatives and ghost fill reach diagonally and 4 cells deep)
  !> and without heat conduction or reaction (their temperature is made over the whole padded
  !> block, m_phase_heat) has
  !> every stencil along one direction and no deeper than the reconstruction's: its plan
  !> holds the faces only, stencil_reach (3) cells deep, and nothing reads the rest.
  !> A scene with level sets (and neither of those nor the cut-cell update) has a second
  !> plan of that kind, plan_flow, for the flow exchange after the ghost fill: until the
  !> next stage's full exchange only the fluxes' pencils read the flow halo (m_step). Not
  !> in the coarray build, whose exchange keeps one set-up (m_comm_caf).
  subroutine sim_plan(sim)
    type(sim_t), intent(inout) :: sim
    logical :: faces, plain
    plain = .not. (sim%cfg%heat_conduction .or. sim%cfg%reaction)
    faces = sim%ls%n == 0 .and. plain
    call halo_plan_build(sim%lay, sim%blocks, sim%plan, faces, &
      merge(stencil_reach, n_halo, faces))
    ! (the coarray back end keeps one exchange set-up per run: one plan there)
    sim%flow_faces = sim%ls%n > 0 .and. plain .and. .not. sim%cut(1)%on .and. &
      comm_backend_name /= 'coarray'
    if (sim%flow_faces) call halo_plan_build(sim%lay, sim%blocks, sim%plan_flow, .true., &
      stencil_reach)
  end subroutine sim_plan

end module m_simulation
