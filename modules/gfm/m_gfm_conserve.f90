!> The conservation fix of the ghost-fluid method (manual/interfaces.md section 2b). The
!> ghost-fluid update is not conservative where a surface moves: a cell that turns real takes
!> a ghost state, a cell that stops being real takes its content with it, and the faces
!> between real cells and ghosts carry fluxes computed with ghost states. After each step the
!> caller (m_step_after) measures the mass and total energy of each solid phase over its real
!> cells, compares them with targets (the run's start plus what came in through the domain's
!> sides), and returns what lies beyond a band to the phase's surface cells (real, within
!> `width` of the surface):
!> - mass: every conserved variable of those cells is scaled by one factor, so velocity,
!>   specific energy, deviatoric stress and plastic strain are unchanged;
!> - energy (over all solid phases together, when nothing outside them can do work on them):
!>   an excess is taken from the internal energy in proportion to each cell's share of it
!>   (the caller says how much; the rest in proportion to mass), a deficit is added to the
!>   internal energy in proportion to mass.
!> conserve_fix does this each step as measure (every block) -> reduce (over blocks and
!> ranks, in block order) -> decide -> apply (every block); content_block and fix_block are
!> its kernels on one block; fix_step_start clears the rates a step gathers (m_step). No I/O;
!> the only collective is m_comm's sum.
module m_gfm_conserve
  use m_kinds, only: wp
  use m_layout, only: layout_t, cell_volume
  use m_blocks, only: block_t
  use m_boundary, only: bc_kind_t, bc_outflow
  use m_phases, only: phases_t
  use m_state, only: i_rho, i_mx, i_mz, i_en
  use m_runge_kutta, only: rk_weights
  use m_levelset_bodies, only: ls_set_t, ls_region, ls_rigid
  use m_gfm, only: gf_t, gf_fit
  use m_comm, only: comm_sum_array
  implicit none
  private
  public :: fix_t, fix_setup, fix_step_start, conserve_fix, content_block, fix_block

  !> per phase and block: mass, energy, surface mass, surface energy, surface internal energy
  integer, parameter, public :: n_content = 5
  !> ... and the phase's real cells on the domain's outflow sides
  integer, parameter :: nq = n_content + 3
  !> largest share of the surface content that one step's fix moves
  real(wp), parameter :: most = 0.1_wp
  !> the band around the targets inside which nothing is done: above the measure's own
  !> noise (a disc of 8 cells' radius flying obliquely reads +-0.4 % mass, +-0.7 % energy)
  real(wp), parameter :: band_mass = 0.005_wp, band_energy = 0.0075_wp

  !> The state of the conservation fix (which parts apply and why, the targets, what it has
  !> taken out so far).
  type :: fix_t
    logical :: on = .false.            !< solid phases with level sets, conserve /= 'none'
    logical :: energy = .false.        !< energy too: no flowing base, no moving rigid body
    character(len=256) :: reason = ''
    real(wp), allocatable :: bflux(:, :, :, :)  !< (2, phase, block, stage): domain-side rates
    real(wp), allocatable :: content(:, :)      !< (2, phase): target mass and energy
    real(wp) :: measure(2) = 0.0_wp    !< the solids' measured mass and energy after the fix
    real(wp), allocatable :: lost(:, :)         !< (2, phase): debris dropped this step
    real(wp), allocatable :: taken(:, :)        !< (2, phase): content taken out so far
    real(wp), allocatable :: open_cells(:)      !< (phase): its real cells on outflow sides
    real(wp), allocatable :: crossing(:)        !< (phase): 1 while it crosses an open side
    real(wp) :: content0(2) = 0.0_wp   !< the solids' mass and energy at the run's start
    integer :: clamped = 0             !< fixes held to a tenth of the surface content
    integer :: aside = 0               !< steps with a solid on an open side: no fix
  end type fix_t

contains

  !> Internal energy per volume, rho E - |rho u|^2 / (2 rho), of one cell.
  pure real(wp) function heat(qc) result(h)
    real(wp), intent(in) :: qc(:)
    h = qc(i_en) - 0.5_wp * sum(qc(i_mx:i_mz)**2) / qc(i_rho)
  end function heat

  !> The content c of one phase over the interior cells of a block: q holds the phase's
  !> conserved variables, bigphi its composite level set (< 0: real). A cell counts with the
  !> fraction f = min(1, max(0, 1/2 - Phi / h)) of its volume, as the bodies' masses of
  !> history.csv do (m_output), so that the measure follows the surface smoothly rather than
  !> by whole cells. A cell just outside the surface (0 <= Phi < h / 2) holds the rest state
  !> after a step; its share is taken at the state of its real face neighbour deepest in the
  !> material (in this block), which the fix moves with the surface cells, so that a fix
  !> changes the measure by exactly what it says; with no such neighbour in the block, at
  !> its own density and no energy.
  pure subroutine content_block(lay, offset, q, bigphi, h, width, c)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3)
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(in) :: bigphi(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp), intent(in) :: h, width
    real(wp), intent(out) :: c(n_content)
    real(wp) :: dv(lay%bsize(1)), f
    integer :: i, j, k, s(3)
    dv = [(cell_volume(lay, offset, i), i = 1, lay%bsize(1))]
    c = 0.0_wp
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        do i = 1, lay%bsize(1)
          if (.not. bigphi(i, j, k) < 0.5_wp * h) cycle
          f = min(1.0_wp, 0.5_wp - bigphi(i, j, k) / h) * dv(i)
          s = [i, j, k]
          if (bigphi(i, j, k) >= 0.0_wp) s = deepest(i, j, k)
          if (s(1) == 0) then
            c(1) = c(1) + f * q(i, j, k, i_rho)
            cycle
          end if
          c(1) = c(1) + f * q(s(1), s(2), s(3), i_rho)
          c(2) = c(2) + f * q(s(1), s(2), s(3), i_en)
          if (bigphi(s(1), s(2), s(3)) < -width) cycle
          c(3) = c(3) + f * q(s(1), s(2), s(3), i_rho)
          c(4) = c(4) + f * q(s(1), s(2), s(3), i_en)
          c(5) = c(5) + f * max(heat(q(s(1), s(2), s(3), :)), 0.0_wp)
        end do
      end do
    end do

  contains

    !> the real face neighbour of (i0, j0, k0) in the block interior with the least Phi
    !> ([0, 0, 0] if none)
    pure function deepest(i0, j0, k0) result(t)
      integer, intent(in) :: i0, j0, k0
      integer :: t(3), d, sg, u(3)
      real(wp) :: best
      t = 0
      best = 0.0_wp
      do d = 1, lay%ndim
        do sg = -1, 1, 2
          u = [i0, j0, k0]
          u(d) = u(d) + sg
          if (u(d) < 1 .or. u(d) > lay%bsize(d)) cycle
          if (bigphi(u(1), u(2), u(3)) < best) then
            best = bigphi(u(1), u(2), u(3))
            t = u
          end if
        end do
      end do
    end function deepest

  end subroutine content_block

  !> Apply the fix to the surface cells of one phase on a block: scale every conserved
  !> variable by fm, then add a_heat times the (non-negative) internal energy and a_mass times
  !> the density to rho E.
  pure subroutine fix_block(lay, q, bigphi, width, fm, a_heat, a_mass)
    type(layout_t), intent(in) :: lay
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(in) :: bigphi(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp), intent(in) :: width, fm, a_heat, a_mass
    integer :: i, j, k
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        do i = 1, lay%bsize(1)
          if (.not. (bigphi(i, j, k) < 0.0_wp .and. bigphi(i, j, k) >= -width)) cycle
          q(i, j, k, :) = fm * q(i, j, k, :)
          q(i, j, k, i_en) = q(i, j, k, i_en) + a_heat * max(heat(q(i, j, k, :)), 0.0_wp) &
            + a_mass * q(i, j, k, i_rho)
        end do
      end do
    end do
  end subroutine fix_block

  !> Which parts of the conservation fix apply, and why (nblocks: this rank's blocks).
  subroutine fix_setup(fix, ph, ls, conserve, nblocks)
    type(fix_t), intent(inout) :: fix
    type(phases_t), intent(in) :: ph
    type(ls_set_t), intent(in) :: ls
    character(len=*), intent(in) :: conserve   !< &numerics conserve
    integer, intent(in) :: nblocks
    integer :: l, np
    logical :: moving
    np = ph%nphase
    allocate(fix%bflux(2, np, nblocks, 3), fix%content(2, np), fix%lost(2, np))
    allocate(fix%taken(2, np), fix%open_cells(np), fix%crossing(np))
    fix%open_cells = 0.0_wp
    fix%crossing = 0.0_wp
    fix%bflux = 0.0_wp
    fix%content = 0.0_wp
    fix%lost = 0.0_wp
    fix%taken = 0.0_wp
    fix%on = any(ph%strong) .and. conserve /= 'none'
    if (.not. fix%on) then
      fix%reason = 'off: no solid phase with a surface'
      if (any(ph%strong)) fix%reason = 'off: &numerics conserve = ''none'''
      return
    end if
    moving = .false.
    do l = 1, ls%n
      if (ls%kind(l) == ls_rigid) moving = moving .or. any(abs(ls%velocity(:, l)) > 0.0_wp)
    end do
    fix%energy = conserve == 'mass_energy' .and. .not. ls%base_flows .and. .not. moving
    fix%reason = 'mass and energy of the solid phases'
    if (fix%energy) return
    fix%reason = 'mass of each solid phase; energy not: '
    if (conserve == 'mass') then
      fix%reason = trim(fix%reason) // ' &numerics conserve = ''mass'''
    else if (ls%base_flows) then
      fix%reason = trim(fix%reason) // ' the base material exchanges work with them'
    else
      fix%reason = trim(fix%reason) // ' a moving rigid body does work on them'
    end if
  end subroutine fix_setup

  !> At a step's start: the step's domain-side rates and dropped debris to zero (nothing
  !> without the fix).
  subroutine fix_step_start(fix)
    type(fix_t), intent(inout) :: fix
    if (.not. fix%on) return
    fix%bflux = 0.0_wp
    fix%lost = 0.0_wp
  end subroutine fix_step_start

  !> The conservation fix after a step of dt (manual/interfaces.md section 2b). Each solid
  !> phase's mass and total energy over its real cells are measured and, when apply is set,
  !> compared with their targets: the values at the run's start plus what came in through
  !> the domain's sides (the Runge-Kutta weighted rates of the stages, fix%bflux) less the
  !> debris taken out (fix%lost). What lies outside a band around the targets (the measure's
  !> own noise) is returned to the phase's surface cells (within two cells of its surface).
  !> The block sums are added in block order whatever the ranks, so results stay
  !> bit-identical on any number of ranks. Without apply, only the measure is kept (the
  !> start). fix%taken keeps what was taken out, for the log and history.csv.
  subroutine conserve_fix(fix, lay, bc, ls, ph, gf, blocks, rk_order, dt, apply, changed)
    type(fix_t), intent(inout) :: fix
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(gf_t), intent(inout) :: gf
    type(block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: rk_order
    real(wp), intent(in) :: dt
    logical, intent(in) :: apply
    logical, intent(out), optional :: changed   !< the fix changed the state
    real(wp) :: part(nq, ph%nphase, lay%nblocks), c(nq, ph%nphase), width, h
    real(wp) :: fm(ph%nphase), a_heat, a_mass
    logical :: touched
    h = maxval(lay%dx(1:lay%ndim))
    width = 2.0_wp * h
    call measure(part)
    call reduce(part, c)
    if (present(changed)) changed = .false.
    if (.not. apply) then
      fix%open_cells = c(nq, :)
      fix%content = c(1:2, :)
      fix%measure = sum(c(1:2, :), dim=2, mask=spread(ph%strong, 1, 2))
      return
    end if
    call decide(c, fm, a_heat, a_mass)
    touched = any(abs(fm - 1.0_wp) > 0.0_wp) .or. abs(a_heat) + abs(a_mass) > 0.0_wp
    if (present(changed)) changed = touched
    if (touched) call put_back(part, fm, a_heat, a_mass)

  contains

    !> each phase's content on each block of this rank (zero elsewhere)
    subroutine measure(pt)
      real(wp), intent(out) :: pt(:, :, :)
      real(wp) :: w(3)
      integer :: b, p, off, id, s
      w = rk_weights(rk_order)
      pt = 0.0_wp
      do b = 1, size(blocks)
        if (gf%dormant(b)) cycle
        call gf_fit(gf, blocks(b)%lay, ph%nflow, ph%nphase)
        id = blocks(b)%id
        do p = 1, ph%nphase
          if (.not. ph%strong(p)) cycle
          off = ph%lo(p) - 1
          call region(b, p)
          call content_block(blocks(b)%lay, blocks(b)%offset, &
            blocks(b)%q(:, :, :, off + 1:off + ph%nflow), gf%work%bigphi(:, :, :, p), &
            h, width, pt(1:n_content, p, id))
          do s = 1, 3
            pt(n_content + 1:n_content + 2, p, id) = pt(n_content + 1:n_content + 2, p, id) &
              + w(s) * fix%bflux(:, p, b, s)
          end do
          pt(nq, p, id) = open_cells(b, p)
        end do
      end do
    end subroutine measure

    !> the blocks' parts summed over the ranks, then over the blocks in block order
    subroutine reduce(pt, cc)
      real(wp), intent(inout) :: pt(:, :, :)
      real(wp), intent(out) :: cc(:, :)
      real(wp) :: flat(size(pt))
      integer :: id
      flat = reshape(pt, [size(pt)])
      call comm_sum_array(flat)
      pt = reshape(flat, shape(pt))
      cc = 0.0_wp
      do id = 1, lay%nblocks
        cc = cc + pt(:, :, id)
      end do
    end subroutine reduce

    !> the targets, and the mass factor of each phase and the energy terms that meet them
    subroutine decide(cc, fmp, ah, am)
      real(wp), intent(in) :: cc(:, :)
      real(wp), intent(out) :: fmp(:), ah, am
      real(wp) :: eps, hs, ms, es, e_new(ph%nphase), lost2(2 * ph%nphase)
      logical :: open_side(ph%nphase)
      integer :: p
      fix%measure(1) = 0.0_wp
      lost2 = reshape(fix%lost, [size(fix%lost)])
      call comm_sum_array(lost2)
      fix%lost = reshape(lost2, shape(fix%lost))
      ! the targets: the content at the start, moved by what crossed the domain's sides and
      ! by the debris taken out; a phase whose cells on the open (outflow) sides of the
      ! domain have changed in number is left alone as long as it has cells there, its
      ! target reset to its measure (what leaves there cannot be told from what the update
      ! loses: the last half cell of a body leaving goes with its level set); a plate
      ! spanning an open side whose edge stays put keeps its fix
      fix%content = fix%content + dt * cc(n_content + 1:n_content + 2, :) - fix%lost
      where (abs(cc(nq, :) - fix%open_cells) > 0.0_wp) fix%crossing = 1.0_wp
      where (.not. cc(nq, :) > 0.0_wp) fix%crossing = 0.0_wp
      open_side = fix%crossing > 0.0_wp .and. ph%strong
      fix%open_cells = cc(nq, :)
      if (any(open_side)) fix%aside = fix%aside + 1
      where (open_side) fix%content(1, :) = cc(1, :)
      if (any(open_side)) fix%content(2, :) = cc(2, :)
      ! mass, phase by phase: a factor on the surface cells
      fmp = 1.0_wp
      do p = 1, ph%nphase
        if (.not. ph%strong(p)) cycle
        eps = 0.0_wp
        if (cc(3, p) > 0.0_wp .and. .not. open_side(p)) then
          eps = outside(cc(1, p), fix%content(1, p), band_mass)
          if (abs(eps) > most * cc(3, p)) fix%clamped = fix%clamped + 1
          eps = max(-most * cc(3, p), min(most * cc(3, p), eps))
          fmp(p) = 1.0_wp - eps / cc(3, p)
        end if
        fix%taken(1, p) = fix%taken(1, p) + eps
        fix%measure(1) = fix%measure(1) + cc(1, p) - eps
      end do
      ! energy, all solid phases together: an excess out of the internal energy, a deficit
      ! into it in proportion to mass
      e_new = cc(2, :) + (fmp - 1.0_wp) * cc(4, :)
      ah = 0.0_wp
      am = 0.0_wp
      if (fix%energy .and. .not. any(open_side)) then
        eps = outside(sum(e_new, mask=ph%strong), sum(fix%content(2, :), mask=ph%strong), &
          band_energy)
        hs = sum(fmp * cc(5, :), mask=ph%strong)
        ms = sum(fmp * cc(3, :), mask=ph%strong)
        es = sum(fmp * abs(cc(4, :)), mask=ph%strong)
        if (eps > 0.0_wp .and. hs > 0.0_wp) then
          ! out of the heat where there is some, the rest (cold material) in proportion to
          ! mass
          ah = -min(eps, most * hs) / hs
          eps = eps + ah * hs
        end if
        if (abs(eps) > most * es) fix%clamped = fix%clamped + 1
        eps = max(-most * es, min(most * es, eps))
        if (ms > 0.0_wp) am = -eps / ms
        do p = 1, ph%nphase
          if (.not. ph%strong(p)) cycle
          fix%taken(2, p) = fix%taken(2, p) - ah * fmp(p) * cc(5, p) - am * fmp(p) * cc(3, p)
          e_new(p) = e_new(p) + ah * fmp(p) * cc(5, p) + am * fmp(p) * cc(3, p)
        end do
      end if
      fix%measure(2) = sum(e_new, mask=ph%strong)
    end subroutine decide

    !> the fix on the surface cells of every block that has some
    subroutine put_back(pt, fmp, ah, am)
      real(wp), intent(in) :: pt(:, :, :), fmp(:), ah, am
      integer :: b, p, off
      do b = 1, size(blocks)
        if (gf%dormant(b)) cycle
        call gf_fit(gf, blocks(b)%lay, ph%nflow, ph%nphase)
        do p = 1, ph%nphase
          ! a block with no surface cell of the phase has nothing to fix
          if (.not. (ph%strong(p) .and. pt(3, p, blocks(b)%id) > 0.0_wp)) cycle
          off = ph%lo(p) - 1
          call region(b, p)
          call fix_block(blocks(b)%lay, blocks(b)%q(:, :, :, off + 1:off + ph%nflow), &
            gf%work%bigphi(:, :, :, p), width, fmp(p), ah, am)
        end do
      end do
    end subroutine put_back

    !> the real cells of phase pp in block bb on the outflow sides of the domain
    real(wp) function open_cells(bb, pp) result(cnt)
      integer, intent(in) :: bb, pp
      integer :: d, n(3), off3(3)
      cnt = 0.0_wp
      n = blocks(bb)%n
      off3 = blocks(bb)%offset
      do d = 1, lay%ndim
        if (bc%lo(d) == bc_outflow .and. off3(d) == 0) cnt = cnt + layer(bb, d, 1, pp)
        if (bc%hi(d) == bc_outflow .and. off3(d) + n(d) == lay%cells(d)) &
          cnt = cnt + layer(bb, d, n(d), pp)
      end do
    end function open_cells

    !> the real cells of phase pp in layer m of direction d of block bb (region() was given
    !> it)
    real(wp) function layer(bb, d, m, pp) result(cnt)
      integer, intent(in) :: bb, d, m, pp
      integer :: lo3(3), hi3(3)
      lo3 = 1
      hi3 = blocks(bb)%n
      lo3(d) = m
      hi3(d) = m
      cnt = real(count(gf%work%bigphi(lo3(1):hi3(1), lo3(2):hi3(2), lo3(3):hi3(3), pp) &
        < 0.0_wp), wp)
    end function layer

    !> how far x lies outside target t (1 -+ band)
    pure real(wp) function outside(x, t, band) result(d)
      real(wp), intent(in) :: x, t, band
      d = x - max(t - band * abs(t), min(t + band * abs(t), x))
    end function outside

    subroutine region(bb, pp)
      integer, intent(in) :: bb, pp
      call ls_region(ls, pp, 1 - lay%ng, blocks(bb)%n + lay%ng, &
        blocks(bb)%q(:, :, :, ph%ils + 1:ph%nvar), gf%work%bigphi(:, :, :, pp), &
        gf%work%owner(:, :, :, pp))
    end subroutine region

  end subroutine conserve_fix

end module m_gfm_conserve
