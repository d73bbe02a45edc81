!> Reinitialisation of a level set to a signed distance on one block (manual/theory.md
!> section 6): the pseudo-time equation phi_tau + S(phi0) (|grad phi| - 1) = 0 with the
!> smoothed sign S = phi0 / sqrt(phi0^2 + |grad phi0|^2 dx^2) (central gradient, dx the
!> smallest active spacing), |grad phi| from the HJ-WENO5 (or ENO3) one-sided derivatives by
!> Godunov upwinding (Rouy and Tourin; Sussman, Smereka and Osher 1994), TVD RK3 in tau.
!> Cells next to the interface (a neighbour along an active axis with phi0 of the opposite
!> sign) use the sub-cell fix of Russo and Smereka (2000): rhs = -(sgn(phi0) |phi| - D) / dx
!> with D = phi0 / |grad phi0| and |grad phi0|^2 = sum_d (max(|phi0(+) - phi0(-)| / 2,
!> |phi0(+) - phi0|, |phi0 - phi0(-)|) / dx_d)^2, which keeps the zero level set in place.
!> With freeze, the cells next to the interface keep their values (the zero level set cannot
!> move at all; the moving bodies of the time loop use this, since the sub-cell fix drifts
!> at the corners of advected bodies). levelset_reinit_step is one RK stage: the caller
!> exchanges the halo of phi before each stage (phi0 needs a valid 1-deep halo once, for the
!> sign and the interface test).
!> levelset_reinit is a convenience for a single block with no neighbours: it fills the halo
!> itself by zero-gradient extrapolation, so it is wrong across block or periodic
!> boundaries. levelset_reinitialise runs the reinitialisation of a run's moving bodies over
!> all blocks on their narrow band, with its own state (the level sets before the first
!> pseudo-step, the RK save space and the band of every block) and a ghost fill of the level
!> sets before every stage.
!> No MPI here.
module m_levelset_reinit
  use m_kinds, only: wp
  use m_reconstruct, only: scheme_weno5
  use m_levelset_derivatives, only: levelset_one_sided
  use m_levelset_advect, only: levelset_rk_stage
  use m_layout, only: layout_t
  use m_blocks, only: block_t
  use m_halo, only: halo_plan_t
  use m_boundary, only: bc_kind_t, fill_ghosts, ghosts_level_sets
  use m_phases, only: phases_t
  use m_tiles, only: near_boxes, tile_cells
  implicit none
  private
  public :: levelset_reinit, levelset_reinit_step, levelset_reinit_rhs
  public :: levelset_halo_zero_gradient, levelset_reinitialise

  !> the margin in cells around the narrow band that the reinitialisation also rebuilds (the
  !> distance it carries the signed distance in one call: band pseudo-steps of half a cell)
  integer, parameter :: band_reach = 3

  !> the boxes (low, high corner, box) of one level set's narrow band on a block
  type :: band_boxes_t
    integer, allocatable :: box(:, :, :)
  end type band_boxes_t

  !> The reinitialisation's state on one block: its level sets before the first pseudo-step
  !> (padded), the Runge-Kutta save space (interior), level set by level set, and the narrow
  !> band: the cells it rebuilds (live) and, for each level set, the tiles' boxes that hold
  !> them.
  type :: reinit_block_t
    real(wp), allocatable :: phi0(:, :, :, :), old(:, :, :, :)
    logical, allocatable :: live(:, :, :, :)
    type(band_boxes_t), allocatable :: tiles(:)
  end type reinit_block_t

contains

  !> Reinitialise the level sets l with moves(l) of every block to signed distances: band
  !> pseudo-steps of half a cell, so the distance is rebuilt out to band / 2 cells (3 for the
  !> default band of 6, the depth of the ghost band), the ghost cells of the level sets filled
  !> (m_boundary) before every RK stage. Only the narrow band is rebuilt: the cells with
  !> |phi| <= band dx at the start (dx the largest spacing), the band in which the time loop
  !> advects the level set (m_levelset_motion), and a margin of band_reach cells round it
  !> (band_cells); beyond them a level set keeps its value, of which only the sign is read.
  !> Each level set's band is computed over the tiles' boxes that hold it (m_tiles), and a
  !> block its band misses costs nothing; so the cost follows the surfaces, not the blocks
  !> times the level sets (interfaces.md 1, "Reinitialisation").
  !> The cells next to the surface are frozen: the zero level set stays where the advection
  !> put it. skip: the dormant blocks, not reinitialised (their halos are filled all the
  !> same): every cell of such a block, halo included, lies beyond every ghost band, where
  !> only the level sets' signs and that test matter, and the block is not advected either;
  !> when a surface comes near, the block wakes while the band is still in its halo, and the
  !> reinitialisations that follow rebuild its distance (performance.md, "Reinitialisation
  !> only where a surface is").
  subroutine levelset_reinitialise(plan, lay, bc, ph, blocks, moves, band, time, skip)
    type(halo_plan_t), intent(inout) :: plan
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(phases_t), intent(in) :: ph
    type(block_t), intent(inout) :: blocks(:)
    logical, intent(in) :: moves(:)
    integer, intent(in) :: band
    real(wp), intent(in) :: time
    logical, intent(in) :: skip(:)
    type(reinit_block_t), allocatable :: rs(:)
    real(wp) :: dtau, width
    integer :: it, stage, b, l, nls
    nls = size(moves)
    width = real(band, wp) * maxval(lay%dx(1:lay%ndim))
    allocate(rs(size(blocks)))
    call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_level_sets, time, skip)
    do b = 1, size(blocks)
      if (skip(b)) cycle
      associate (n => blocks(b)%n, r => rs(b))
        r%phi0 = blocks(b)%q(:, :, :, ph%ils + 1:ph%nvar)
        allocate(r%old(n(1), n(2), n(3), nls), source=0.0_wp)
        allocate(r%tiles(nls))
        allocate(r%live(n(1), n(2), n(3), nls))
        do l = 1, nls
          if (.not. moves(l)) cycle
          r%live(:, :, :, l) = band_cells(lay%ndim, n, lay%ng, r%phi0(:, :, :, l), width)
          r%tiles(l)%box = near_boxes(r%live(:, :, :, l), tile_cells)
        end do
      end associate
    end do
    dtau = 0.5_wp * minval(lay%dx(1:lay%ndim))
    do it = 1, band
      do stage = 1, 3
        if (it > 1 .or. stage > 1) &
          call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_level_sets, time, skip)
        do b = 1, size(blocks)
          if (skip(b)) cycle
          do l = 1, nls
            if (.not. moves(l)) cycle
            call band_stage(lay%ndim, blocks(b)%n, lay%ng, lay%dx, rs(b)%phi0(:, :, :, l), &
              rs(b)%live(:, :, :, l), rs(b)%tiles(l)%box, stage, dtau, &
              blocks(b)%q(:, :, :, ph%ils + l), rs(b)%old(:, :, :, l))
          end do
        end do
      end do
    end do
  end subroutine levelset_reinitialise

  !> The cells of a block that the reinitialisation rebuilds: those within band_reach cells
  !> (a box, along the active axes) of a cell of the padded block with |phi0| <= width. The
  !> margin keeps the values the band moves into current: a cell beyond the band is neither
  !> advected nor rebuilt, so without it a surface coming nearer would find the cell's old,
  !> too large distance there (the 400 m/s Taylor bar's spreading foot did, and its cut cells
  !> failed); with it, every cell within band_reach of the band has been rebuilt at the last
  !> reinitialisation, while a surface moves a fraction of a cell between two of them.
  function band_cells(ndim, n, g, phi0, width) result(live)
    integer, intent(in) :: ndim, n(3), g(3)
    real(wp), intent(in) :: phi0(1-g(1):, 1-g(2):, 1-g(3):)
    real(wp), intent(in) :: width
    logical :: live(n(1), n(2), n(3))
    logical, allocatable :: m(:, :, :), a(:, :, :), c(:, :, :)
    integer :: r(3), s
    r = 0
    r(1:ndim) = min(band_reach, g(1:ndim))
    m = abs(phi0(1-r(1):n(1)+r(1), 1-r(2):n(2)+r(2), 1-r(3):n(3)+r(3))) <= width
    ! (m starts at 1: the padded cell 1 - r is its first) the margin axis by axis
    allocate(a(n(1), n(2) + 2 * r(2), n(3) + 2 * r(3)), source=.false.)
    do s = 0, 2 * r(1)
      a = a .or. m(1+s:n(1)+s, :, :)
    end do
    allocate(c(n(1), n(2), n(3) + 2 * r(3)), source=.false.)
    do s = 0, 2 * r(2)
      c = c .or. a(:, 1+s:n(2)+s, :)
    end do
    live = .false.
    do s = 0, 2 * r(3)
      live = live .or. c(:, :, 1+s:n(3)+s)
    end do
  end function band_cells

  !> One RK3 stage of the frozen reinitialisation of one level set on its narrow band: the
  !> right-hand side over each box (with its halo of g cells), then the update of the live
  !> cells (every right-hand side from the level set before the stage). A cell's right-hand
  !> side reads only its stencil, so it is the same whichever box holds it.
  subroutine band_stage(ndim, n, g, dx, phi0, live, boxes, stage, dtau, phi, phi_old)
    integer, intent(in) :: ndim, n(3), g(3), stage
    real(wp), intent(in) :: dx(3), dtau
    real(wp), intent(in) :: phi0(1-g(1):, 1-g(2):, 1-g(3):)
    logical, intent(in) :: live(:, :, :)
    integer, intent(in) :: boxes(:, :, :)
    real(wp), intent(inout) :: phi(1-g(1):, 1-g(2):, 1-g(3):)
    real(wp), intent(inout) :: phi_old(:, :, :)
    real(wp), allocatable :: rhs(:, :, :), sub(:, :, :), sub0(:, :, :), r(:, :, :)
    integer :: ib, lo(3), hi(3)
    if (size(boxes, 3) == 0) return
    allocate(rhs(n(1), n(2), n(3)), source=0.0_wp)
    do ib = 1, size(boxes, 3)
      lo = boxes(1, :, ib)
      hi = boxes(2, :, ib)
      sub = phi(lo(1)-g(1):hi(1)+g(1), lo(2)-g(2):hi(2)+g(2), lo(3)-g(3):hi(3)+g(3))
      sub0 = phi0(lo(1)-g(1):hi(1)+g(1), lo(2)-g(2):hi(2)+g(2), lo(3)-g(3):hi(3)+g(3))
      allocate(r(hi(1) - lo(1) + 1, hi(2) - lo(2) + 1, hi(3) - lo(3) + 1))
      call levelset_reinit_rhs(ndim, hi - lo + 1, g, dx, sub0, sub, r, scheme_weno5, .true.)
      rhs(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)) = r
      deallocate(r)
    end do
    ! (every cell's rate from the level set before the stage; beyond the boxes it is 0 and
    ! unread, beyond the live cells nothing changes)
    call levelset_rk_stage(n, g, stage, dtau, phi, phi_old, rhs, live)
  end subroutine band_stage

  !> iterations pseudo-time RK3 steps of size cfl * min(dx) on one isolated block.
  subroutine levelset_reinit(ndim, n, g, dx, phi, iterations, cfl, scheme)
    integer, intent(in) :: ndim, n(3), g(3), iterations
    real(wp), intent(in) :: dx(3), cfl
    real(wp), intent(inout) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    integer, intent(in), optional :: scheme
    real(wp), allocatable :: phi0(:, :, :), phi_old(:, :, :)
    real(wp) :: dtau
    integer :: it, stage, sch
    sch = scheme_weno5
    if (present(scheme)) sch = scheme
    dtau = cfl * minval(dx(1:ndim))
    call levelset_halo_zero_gradient(ndim, n, g, phi)
    phi0 = phi
    allocate(phi_old(n(1), n(2), n(3)))
    do it = 1, iterations
      do stage = 1, 3
        call levelset_halo_zero_gradient(ndim, n, g, phi)
        call levelset_reinit_step(ndim, n, g, dx, phi0, stage, dtau, phi, phi_old, sch)
      end do
    end do
    call levelset_halo_zero_gradient(ndim, n, g, phi)
  end subroutine levelset_reinit

  !> One RK3 stage (1, 2, 3) of the reinitialisation; phi0 is the level set before the
  !> first iteration, phi_old the RK save space kept by the caller between stages.
  subroutine levelset_reinit_step(ndim, n, g, dx, phi0, stage, dtau, phi, phi_old, scheme, &
      freeze)
    integer, intent(in) :: ndim, n(3), g(3), stage
    real(wp), intent(in) :: dx(3), dtau
    real(wp), intent(in) :: phi0(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(inout) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(inout) :: phi_old(n(1), n(2), n(3))
    integer, intent(in), optional :: scheme
    logical, intent(in), optional :: freeze   !< keep the cells next to the interface as they are
    real(wp), allocatable :: rhs(:, :, :)
    integer :: sch
    logical :: frz
    sch = scheme_weno5
    if (present(scheme)) sch = scheme
    frz = .false.
    if (present(freeze)) frz = freeze
    allocate(rhs(n(1), n(2), n(3)))
    call levelset_reinit_rhs(ndim, n, g, dx, phi0, phi, rhs, sch, frz)
    call levelset_rk_stage(n, g, stage, dtau, phi, phi_old, rhs)
  end subroutine levelset_reinit_step

  !> rhs = -S(phi0) (|grad phi|_Godunov - 1), or the Russo-Smereka form next to the interface.
  subroutine levelset_reinit_rhs(ndim, n, g, dx, phi0, phi, rhs, scheme, freeze)
    integer, intent(in) :: ndim, n(3), g(3), scheme
    logical, intent(in) :: freeze
    real(wp), intent(in) :: dx(3)
    real(wp), intent(in) :: phi0(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(in) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    real(wp), intent(out) :: rhs(n(1), n(2), n(3))
    real(wp), allocatable :: dm(:, :, :), dp(:, :, :), gpos(:, :, :), gneg(:, :, :)
    real(wp), parameter :: tiny_grad = 1.0e-30_wp
    real(wp) :: h, s, c, pm, pp, p, gc2, gs2, delta
    integer :: d, i, j, k, e(3)
    logical :: near
    allocate(dm(n(1), n(2), n(3)), dp(n(1), n(2), n(3)))
    allocate(gpos(n(1), n(2), n(3)), gneg(n(1), n(2), n(3)))
    h = minval(dx(1:ndim))
    gpos = 0.0_wp
    gneg = 0.0_wp
    do d = 1, ndim
      call levelset_one_sided(scheme, d, n, g, dx, phi, dm, dp)
      ! Godunov: for S > 0 the characteristic leaves the interface, so take the backward
      ! slope where it rises and the forward slope where it falls
      gpos = gpos + max(max(dm, 0.0_wp)**2, min(dp, 0.0_wp)**2)
      gneg = gneg + max(min(dm, 0.0_wp)**2, max(dp, 0.0_wp)**2)
    end do
    do k = 1, n(3)
      do j = 1, n(2)
        do i = 1, n(1)
          p = phi0(i, j, k)
          near = abs(p) <= 0.0_wp
          gc2 = 0.0_wp
          gs2 = 0.0_wp
          do d = 1, ndim
            e = 0
            e(d) = 1
            pm = phi0(i-e(1), j-e(2), k-e(3))
            pp = phi0(i+e(1), j+e(2), k+e(3))
            near = near .or. p * pm < 0.0_wp .or. p * pp < 0.0_wp
            c = 0.5_wp * (pp - pm) / dx(d)
            gc2 = gc2 + c**2
            delta = max(0.5_wp * abs(pp - pm), abs(pp - p), abs(p - pm)) / dx(d)
            gs2 = gs2 + delta**2
          end do
          if (near .and. freeze) then
            rhs(i, j, k) = 0.0_wp
          else if (near) then
            ! Russo-Smereka: relax towards the distance implied by phi0 and its slope
            rhs(i, j, k) = -(sign(1.0_wp, p) * abs(phi(i, j, k)) &
              - p / sqrt(max(gs2, tiny_grad))) / h
          else
            s = p / sqrt(p**2 + gc2 * h**2)
            if (s >= 0.0_wp) then
              rhs(i, j, k) = -s * (sqrt(gpos(i, j, k)) - 1.0_wp)
            else
              rhs(i, j, k) = -s * (sqrt(gneg(i, j, k)) - 1.0_wp)
            end if
          end if
        end do
      end do
    end do
  end subroutine levelset_reinit_rhs

  !> Copy the outermost interior layer into the halo of every active direction (edges and
  !> corners included, since each direction copies whole planes of the padded array).
  subroutine levelset_halo_zero_gradient(ndim, n, g, phi)
    integer, intent(in) :: ndim, n(3), g(3)
    real(wp), intent(inout) :: phi(1-g(1):n(1)+g(1), 1-g(2):n(2)+g(2), 1-g(3):n(3)+g(3))
    integer :: l
    if (ndim >= 1) then
      do l = 1, g(1)
        phi(1-l, :, :) = phi(1, :, :)
        phi(n(1)+l, :, :) = phi(n(1), :, :)
      end do
    end if
    if (ndim >= 2) then
      do l = 1, g(2)
        phi(:, 1-l, :) = phi(:, 1, :)
        phi(:, n(2)+l, :) = phi(:, n(2), :)
      end do
    end if
    if (ndim >= 3) then
      do l = 1, g(3)
        phi(:, :, 1-l) = phi(:, :, 1)
        phi(:, :, n(3)+l) = phi(:, :, n(3))
      end do
    end if
  end subroutine levelset_halo_zero_gradient

end module m_levelset_reinit
