!> The simulation as one object: the resolved deck, the block layout, this rank's blocks,
!> the halo plan, the equation of state, boundary conditions and scheme choices, and the
!> clock (time, step, output schedule). sim_setup turns a deck into a ready-to-run
!> simulation: layout, rigid-obstacle blocks, the memory estimate (a deck that does not fit
!> the node is refused before anything is allocated), METIS partition, allocation and the
!> initial state painted from the bodies (or read from a checkpoint by m_output).
module m_simulation
  use m_kinds, only: wp, i8, name_len
  use m_config, only: config_t, material_t, material_index
  use m_layout, only: layout_t, layout_init, block_offset, block_extent
  use m_blocks, only: block_t, blocks_allocate
  use m_halo, only: halo_plan_t, halo_plan_build
  use m_partition, only: partition_blocks
  use m_boundary, only: bc_kind_t, bc_from_name
  use m_eos, only: eos_t, eos_from_material, eos_energy, eos_prepare
  use m_euler, only: euler_work_t, euler_work_init
  use m_reconstruct, only: scheme_from_name
  use m_flux, only: flux_from_name, scalar_flux_from_name
  use m_scene, only: inside_body, cell_centre, body_distance, rigid_block_status
  use m_levelset_bodies, only: ls_set_t, ls_material, ls_void, ls_rigid, ls_region
  use m_gfm, only: gfm_work_t, gfm_work_init, gfm_counts_t, gfm_scene_t, probe_from_name
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, n_euler, n_solid
  use m_yield, only: strength_t, strength_from_material, strength_none
  use m_timers, only: timers_t, memory_kb, node_memory_kb
  use m_comm, only: comm_rank, comm_size, comm_node_ranks
  use m_errors, only: stop_collective
  use m_deck_text, only: base_name, int_text
  implicit none
  private
  public :: sim_t, sim_setup, sim_paint_initial_state, sim_block_work, mem_parts, mem_text

  !> the parts of the memory estimate (sim_memory_estimate), in the order of sim_t%mem
  character(len=*), parameter :: mem_parts(6) = [character(len=10) :: 'state', 'halos', &
    'level_sets', 'output', 'work', 'layout']

  !> Depth of the ghost band in cells: the reach (3) of the ENO3 and WENO5 stencils of a real
  !> cell next to the surface, and a half cell for oblique surfaces.
  real(wp), parameter :: ghost_depth = 3.5_wp

  type :: sim_t
    type(config_t) :: cfg
    type(layout_t) :: lay
    type(block_t), allocatable :: blocks(:)
    type(halo_plan_t) :: plan
    type(euler_work_t) :: work
    type(bc_kind_t) :: bc
    integer :: nvar = n_euler          !< flow variables of every phase, then the level sets
    integer :: nflow = n_euler         !< flow variables of a phase: n_euler, or n_solid
    integer :: nphase = 1              !< phases (flow states): base material, material bodies
    integer :: ils = n_euler           !< level set l is variable ils + l
    ! per phase p: its material, equation of state, strength, shear modulus (0 without
    ! strength) and rest state (density, pressure) of its non-computed cells
    character(len=name_len), allocatable :: material(:)
    type(eos_t), allocatable :: eos(:)
    type(strength_t), allocatable :: st(:)
    real(wp), allocatable :: shear(:)
    logical, allocatable :: strong(:)
    real(wp), allocatable :: rest(:, :)
    type(ls_set_t) :: ls               !< level-set bodies (m_levelset_bodies)
    type(gfm_scene_t) :: scn           !< what the ghost fill needs of the phases
    type(gfm_work_t) :: gwork
    type(gfm_counts_t) :: gcount
    real(wp), allocatable :: vel(:, :, :, :)   !< level-set advection velocity (padded block)
    real(wp), allocatable :: ls_rhs(:, :, :)
    logical, allocatable :: dormant(:)         !< block entirely beyond the ghost band
    ! the conservation fix of the ghost-fluid method (m_gfm_conserve; m_timeloop)
    logical :: fix_mass = .false.      !< solid phases with level sets, conserve /= 'none'
    logical :: fix_energy = .false.    !< energy too: no flowing base, no moving rigid body
    character(len=256) :: fix_reason = ''
    real(wp), allocatable :: bflux(:, :, :, :)  !< (2, phase, block, stage): domain-side rates
    real(wp), allocatable :: content(:, :)      !< (2, phase): target mass and energy
    real(wp) :: measure(2) = 0.0_wp    !< the solids' measured mass and energy after the fix
    real(wp), allocatable :: lost(:, :)         !< (2, phase): debris dropped this step
    real(wp), allocatable :: fixed(:, :)        !< (2, phase): content taken out so far
    real(wp), allocatable :: open_cells(:)      !< (phase): its real cells on outflow sides
    real(wp), allocatable :: crossing(:)        !< (phase): 1 while it crosses an open side
    real(wp) :: content0(2) = 0.0_wp   !< the solids' mass and energy at the run's start
    integer :: fix_clamped = 0         !< fixes held to a tenth of the surface content
    integer :: fix_aside = 0           !< steps with a solid on an open side: no fix
    logical :: has_strength = .false.  !< the state carries rho S and rho eps_p
    character(len=256) :: strength_reason = ''
    integer :: scheme = 3, flux = 1
    integer :: scalar_flux = 1         !< solids: flux of rho eps_p, rho w_c (m_flux)
    real(wp) :: time = 0.0_wp, dt = 0.0_wp, dt_first = 0.0_wp
    integer :: step = 0
    integer :: plot_count = 0          !< plot files written so far
    integer :: last_plot_step = -1
    real(wp) :: next_plot_time = 0.0_wp
    integer(i8) :: cell_steps = 0      !< this rank's cells x steps, for the cost report
    integer(i8) :: fallback_faces = 0  !< faces reconstructed at first order (this rank)
    integer(i8) :: fallback_step = 0   !< the same, in the last step, summed over ranks
    integer :: first_order_steps = 0   !< steps recomputed at first order (a-posteriori)
    integer(i8) :: cells_low = 0       !< cells redone with first-order faces (this rank)
    real(wp), allocatable :: qsave(:, :, :, :)   !< a block's stage input (interior)
    logical, allocatable :: trouble(:, :, :)     !< its cells left inadmissible
    logical :: step_failed = .false.   !< the last step met a state with no admissible cells
    integer :: restart_step = 0
    type(timers_t) :: timers
    real(wp) :: wall_start = 0.0_wp
    ! the memory estimate of one rank in bytes, part by part (mem_parts), made before the
    ! grid is allocated; the resident memory then; what the node has, and its ranks
    real(wp) :: mem(size(mem_parts)) = 0.0_wp
    real(wp) :: mem_base = 0.0_wp
    real(wp) :: node_available = 0.0_wp
    integer :: node_ranks = 1
  end type sim_t

contains

  subroutine sim_setup(cfg, sim)
    type(config_t), intent(in) :: cfg
    type(sim_t), intent(inout) :: sim
    logical :: periodic(3)
    integer :: d, p, id
    integer, allocatable :: work(:)
    type(material_t) :: mat
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
    sim%nphase = sim%ls%nphase
    allocate(sim%eos(sim%nphase), sim%st(sim%nphase), sim%shear(sim%nphase), &
      sim%strong(sim%nphase), sim%rest(2, sim%nphase))
    sim%strength_reason = ''
    do p = 1, sim%nphase
      mat = cfg%materials(material_index(cfg, sim%material(p)))
      sim%st(p) = strength_from_material(mat)
      sim%strong(p) = cfg%strength .and. sim%st(p)%model /= strength_none
      sim%shear(p) = 0.0_wp
      if (sim%strong(p)) sim%shear(p) = sim%st(p)%g
      sim%eos(p) = eos_from_material(mat)
      call eos_prepare(sim%eos(p))
      sim%rest(:, p) = [mat%rho0, mat%p0]
      if (any(sim%material(1:p-1) == sim%material(p))) cycle
      if (len_trim(sim%strength_reason) > 0) &
        sim%strength_reason = trim(sim%strength_reason) // '; '
      sim%strength_reason = trim(sim%strength_reason) // ' ' // trim(strength_text(p))
    end do
    sim%strength_reason = adjustl(sim%strength_reason)
    sim%has_strength = any(sim%strong)
    if (sim%has_strength) sim%nflow = n_solid
    sim%ils = sim%nphase * sim%nflow
    sim%nvar = sim%ils + sim%ls%n
    call sim_memory_estimate(sim)
    call memory_check(sim)
    allocate(work(sim%lay%nblocks))
    work = [(product(block_extent(sim%lay, id)), id = 1, sim%lay%nblocks)]
    call partition_blocks(sim%lay, work)
    call blocks_allocate(sim%lay, comm_rank(), sim%nvar, sim%blocks)
    call halo_plan_build(sim%lay, sim%blocks, sim%plan)
    call shape_work(sim, sim%lay)
    if (sim%ls%n > 0) then
      sim%scn%eos = sim%eos
      sim%scn%shear = sim%shear
      sim%scn%rest = sim%rest
      sim%scn%nflow = sim%nflow
      sim%scn%probe = probe_from_name(cfg%gfm_probe)
      sim%scn%band = ghost_depth * maxval(sim%lay%dx(1:sim%lay%ndim))
      sim%scn%contact = cfg%contact_kappa * maxval(sim%lay%dx(1:sim%lay%ndim))
      allocate(sim%dormant(size(sim%blocks)))
      sim%dormant = .false.
      call fix_setup(sim)
    end if
    sim%scheme = scheme_from_name(cfg%scheme)
    sim%flux = flux_from_name(cfg%flux)
    sim%scalar_flux = scalar_flux_from_name(cfg%scalar_flux)

  contains

    !> the run log's reason for strength of phase pp's material
    function strength_text(pp) result(t)
      integer, intent(in) :: pp
      character(len=128) :: t
      if (sim%strong(pp)) then
        t = 'on: material ' // trim(mat%name) // ' has ' // trim(mat%strength_model)
      else if (sim%st(pp)%model /= strength_none) then
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
    if (all(shape(sim%trouble) == sim%blocks(b)%n)) return
    call shape_work(sim, sim%blocks(b)%lay)
  end subroutine sim_block_work

  !> The shared work arrays for a block of layout (or view) bl.
  subroutine shape_work(sim, bl)
    type(sim_t), intent(inout) :: sim
    type(layout_t), intent(in) :: bl
    integer :: lo(3), hi(3), n(3)
    n = bl%bsize
    lo = 1 - bl%ng
    hi = n + bl%ng
    if (allocated(sim%qsave)) deallocate(sim%qsave, sim%trouble)
    call euler_work_init(bl, sim%nflow, sim%work)
    allocate(sim%qsave(n(1), n(2), n(3), sim%nvar), sim%trouble(n(1), n(2), n(3)))
    if (sim%ls%n == 0) return
    if (allocated(sim%vel)) deallocate(sim%vel, sim%ls_rhs)
    call gfm_work_init(bl, sim%nflow, sim%nphase, sim%gwork)
    allocate(sim%vel(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), 3), sim%ls_rhs(n(1), n(2), n(3)))
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
    integer :: b, n, id, i, j, k, off(3), np, ext(3)
    real(wp) :: deep, dmax
    logical, allocatable :: whole(:)
    character(len=:), allocatable :: base
    base = trim(base_name(cfg%deck_file))
    call stop_collective('ERROR ' // base // ' &domain base_material: with a void base ' // &
      'some &body must be of a material', cfg%base_material /= 'void' .or. &
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
          whole(b) = all([(rigid_block_status(sim%lay, id, body) /= 1, id = 1, &
          sim%lay%nblocks)])
        if (.not. whole(b)) cycle
        do id = 1, sim%lay%nblocks
          if (rigid_block_status(sim%lay, id, body) == 2) sim%lay%active(id) = .false.
        end do
      end associate
    end do
    n = count([(own_level_set(b) .and. .not. whole(b), b = 1, cfg%n_bodies)])
    sim%ls%n = n
    allocate(sim%ls%kind(n), sim%ls%body(n), sim%ls%name(n), sim%ls%velocity(3, n), &
      sim%ls%phase(n))
    allocate(sim%material(n + 1))
    np = 0
    if (sim%ls%base_flows) then
      np = 1
      sim%material(1) = cfg%base_material
    end if
    n = 0
    do b = 1, cfg%n_bodies
      associate (body => cfg%bodies(b))
        if (.not. own_level_set(b) .or. whole(b)) cycle
        n = n + 1
        sim%ls%body(n) = b
        sim%ls%name(n) = body%name
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
          sim%material(np) = body%material
        end select
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
                dmax = max(dmax, body_distance(body, sim%lay%ndim, &
                  cell_centre(sim%lay, off, i, j, k)))
              end do
            end do
          end do
          if (dmax < deep) sim%lay%active(id) = .false.
        end do
      end associate
    end do
    sim%ls%nphase = np
    sim%material = sim%material(1:np)

  contains

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
    integer :: b, i, j, k, nb, l, m, p, off, own(1, 1, 1)
    real(wp) :: x(3), rho, vel(3), pres, e(1), phi(1, 1, 1, sim%ls%n), bigphi(1, 1, 1)
    real(wp) :: rest(2)
    real(wp), parameter :: two_pi = 8.0_wp * atan(1.0_wp)
    do b = 1, size(sim%blocks)
      associate (blk => sim%blocks(b))
        do k = 1, blk%n(3)
          do j = 1, blk%n(2)
            do i = 1, blk%n(1)
              x = cell_centre(sim%lay, blk%offset, i, j, k)
              do l = 1, sim%ls%n
                phi(1, 1, 1, l) = body_distance(sim%cfg%bodies(sim%ls%body(l)), &
                  sim%lay%ndim, x)
                if (sim%ls%kind(l) /= ls_material) cycle
                do m = 1, l - 1
                  if (sim%ls%kind(m) == ls_material) &
                    phi(1, 1, 1, m) = max(phi(1, 1, 1, m), -phi(1, 1, 1, l))
                end do
              end do
              blk%q(i, j, k, sim%ils + 1:sim%nvar) = phi(1, 1, 1, :)
              do p = 1, sim%nphase
                rest = sim%rest(:, p)
                rho = rest(1)
                pres = rest(2)
                vel = 0.0_wp
                do nb = 1, sim%cfg%n_bodies
                  if (.not. paints(nb, p)) cycle
                  associate (body => sim%cfg%bodies(nb))
                    if (.not. inside_body(body, sim%lay%ndim, x)) cycle
                    ! the exact cell average of the sinusoid, so that smooth data start at
                    ! the order of the scheme rather than at second order
                    rho = body%rho * (1.0_wp + body%amplitude &
                      * sin(two_pi * dot_product(body%wavevector, x)) &
                      * product(sinc(0.5_wp * two_pi * body%wavevector * sim%lay%dx)))
                    pres = body%p
                    vel = body%velocity
                  end associate
                end do
                if (sim%ls%n > 0) then
                  call ls_region(sim%ls, p, [1, 1, 1], [1, 1, 1], phi, bigphi, own)
                  if (bigphi(1, 1, 1) >= 0.0_wp) then
                    rho = rest(1)
                    pres = rest(2)
                    vel = 0.0_wp
                  end if
                end if
                call eos_energy(sim%eos(p), 1, [rho], [pres], e)
                off = (p - 1) * sim%nflow
                blk%q(i, j, k, off + 1:off + sim%nflow) = 0.0_wp
                blk%q(i, j, k, off + i_rho) = rho
                blk%q(i, j, k, off + i_mx) = rho * vel(1)
                blk%q(i, j, k, off + i_my) = rho * vel(2)
                blk%q(i, j, k, off + i_mz) = rho * vel(3)
                blk%q(i, j, k, off + i_en) = rho * (e(1) + 0.5_wp * sum(vel**2))
              end do
            end do
          end do
        end do
      end associate
    end do

  contains

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

  !> What one rank will hold once the grid is allocated, in bytes (manual/user-guide.md,
  !> "Memory"): the blocks' state with halo, start-of-step copy and right-hand side; the
  !> packed halo messages to other ranks (send and receive) of a compact piece of blocks;
  !> the copy of the level sets that reinitialisation keeps; one field of every block that
  !> plot files and checkpoints gather; the per-block work arrays of the fluxes and the
  !> ghost fill; the whole-grid block tables and the METIS graph. A rank is taken to hold
  !> its share of the active blocks, rounded up (METIS balances the cells).
  subroutine sim_memory_estimate(sim)
    type(sim_t), intent(inout) :: sim
    real(wp), parameter :: b8 = 8.0_wp
    real(wp) :: nb, ni, np, nd, halo_cells
    logical :: leader
    nd = real(sim%lay%ndim, wp)
    nb = real(ceiling(real(count(sim%lay%active), wp) / comm_size()), wp)
    ni = product(real(sim%lay%nmax, wp))
    np = product(real(sim%lay%nmax + 2 * sim%lay%ng, wp))
    sim%mem(1) = b8 * nb * sim%nvar * (np + 2.0_wp * ni)
    ! the blocks on the surface of a compact piece of nb blocks, one face halo each
    halo_cells = 0.0_wp
    if (comm_size() > 1) halo_cells = min(nb, 2.0_wp * nd * nb**((nd - 1.0_wp) / nd)) &
      * (np - ni) / (2.0_wp * nd)
    sim%mem(2) = 2.0_wp * b8 * sim%nvar * halo_cells
    sim%mem(3) = b8 * sim%ls%n * np * nb
    sim%mem(4) = b8 * ni * nb
    sim%mem(5) = b8 * (np * (sim%nflow * (1 + sim%nphase) + 2 * sim%nphase + 3) &
      + ni * (sim%nvar + 2))
    ! active and owner, and METIS's graph (offsets, 6 neighbours and weights, vertex
    ! weights, parts, and its own copies) of every block of the grid
    sim%mem(6) = 100.0_wp * sim%lay%nblocks
    sim%mem_base = 1024.0_wp * memory_kb('VmRSS')
    call comm_node_ranks(sim%node_ranks, leader)
    sim%node_available = 1024.0_wp * node_memory_kb('MemAvailable')
    if (.not. sim%node_available > 0.0_wp) &
      sim%node_available = 1024.0_wp * node_memory_kb('MemTotal')
  end subroutine sim_memory_estimate

  !> Refuse, on every rank, a run whose ranks on one node would need more than the node has
  !> available (when the node says: /proc/meminfo).
  subroutine memory_check(sim)
    type(sim_t), intent(in) :: sim
    real(wp) :: need
    need = sim%node_ranks * sum(sim%mem)
    call stop_collective('ERROR ' // trim(base_name(sim%cfg%deck_file)) // ' &domain cells: ' &
      // 'the run needs an estimated ' // mem_text(need) // ' on this node (' &
      // int_text(sim%node_ranks) // trim(merge(' rank  ', ' ranks ', sim%node_ranks == 1)) &
      // ' of ' // mem_text(sum(sim%mem)) // ' each) ' &
      // 'but the node has ' // mem_text(sim%node_available) // ' available ' &
      // '(/proc/meminfo MemAvailable): use fewer cells, or more nodes', &
      .not. (sim%node_available > 0.0_wp .and. need > sim%node_available))
  end subroutine memory_check

  !> bytes with about 3 digits and a unit: '9766 GiB', '23.4 GiB', '512 MiB', '1.25 MiB'
  function mem_text(bytes) result(r)
    real(wp), intent(in) :: bytes
    character(len=:), allocatable :: r
    character(len=32) :: buf
    character(len=4) :: unit
    real(wp) :: x
    x = bytes / 1024.0_wp**3
    unit = ' GiB'
    if (x < 1.0_wp) then
      x = bytes / 1024.0_wp**2
      unit = ' MiB'
    end if
    if (x >= 100.0_wp) then
      write(buf, '(i0)') nint(x, i8)
    else if (x >= 10.0_wp) then
      write(buf, '(f0.1)') x
    else
      write(buf, '(f4.2)') x
    end if
    r = trim(adjustl(buf)) // unit
  end function mem_text

  !> Which parts of the conservation fix apply (m_gfm_conserve), and why.
  subroutine fix_setup(sim)
    type(sim_t), intent(inout) :: sim
    integer :: l
    logical :: moving
    allocate(sim%bflux(2, sim%nphase, size(sim%blocks), 3), sim%content(2, sim%nphase))
    allocate(sim%lost(2, sim%nphase), sim%fixed(2, sim%nphase), sim%open_cells(sim%nphase))
    allocate(sim%crossing(sim%nphase))
    sim%open_cells = 0.0_wp
    sim%crossing = 0.0_wp
    sim%bflux = 0.0_wp
    sim%content = 0.0_wp
    sim%lost = 0.0_wp
    sim%fixed = 0.0_wp
    sim%fix_mass = any(sim%strong) .and. sim%cfg%conserve /= 'none'
    if (.not. sim%fix_mass) then
      sim%fix_reason = 'off: no solid phase with a surface'
      if (any(sim%strong)) sim%fix_reason = 'off: &numerics conserve = ''none'''
      return
    end if
    moving = .false.
    do l = 1, sim%ls%n
      if (sim%ls%kind(l) == ls_rigid) moving = moving .or. any(abs(sim%ls%velocity(:, l)) > 0.0_wp)
    end do
    sim%fix_energy = sim%cfg%conserve == 'mass_energy' .and. .not. sim%ls%base_flows &
      .and. .not. moving
    sim%fix_reason = 'mass and energy of the solid phases'
    if (sim%fix_energy) return
    sim%fix_reason = 'mass of each solid phase; energy not: '
    if (sim%cfg%conserve == 'mass') then
      sim%fix_reason = trim(sim%fix_reason) // ' &numerics conserve = ''mass'''
    else if (sim%ls%base_flows) then
      sim%fix_reason = trim(sim%fix_reason) // ' the base material exchanges work with them'
    else
      sim%fix_reason = trim(sim%fix_reason) // ' a moving rigid body does work on them'
    end if
  end subroutine fix_setup

end module m_simulation
