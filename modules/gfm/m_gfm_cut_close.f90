!> The closing cells of the cut-cell update (issue 15, manual/theory.md section 7d): where a
!> void closes, a wet cell whose centre lies in the void shows a ghost state to the stencils,
!> so the content its faces bring does not push back; until the void's level set closes it,
!> it shares content with its wet face neighbours (relax_closing, called by m_gfm_cut's
!> cut_open on the content of a block as it came from the stage). A void's level set
!> follows the content at the step's end and closes such remnants (cut_follow, called by
!> m_gfm_stage).
module m_gfm_cut_close
  use m_kinds, only: wp
  use m_layout, only: layout_t, cell_volume
  use m_blocks, only: block_t
  use m_levelset_bodies, only: ls_set_t, ls_material, ls_void
  use m_state, only: i_rho, i_mx, i_mz, i_en
  use m_eos, only: eos_t, eos_pressure, eos_sound_speed2
  use m_gfm_cut_cells, only: full
  implicit none
  private
  public :: relax_closing, cut_follow, cut_follow_body, content_sounds

  !> a body's level set shrinks towards its content only beyond this many times the dead band
  !> (&numerics body_follow) it grows beyond: cut_follow_body
  real(wp), parameter, public :: body_shrink = 6.0_wp

contains

  !> A cell every corner of which lies in the phase while its centre lies outside (a
  !> remnant of a void narrower than the cell, closing; cut_follow closes it at the step's
  !> end) shows a ghost state to the stencils, so the content its faces bring does not push
  !> back, and piles up. Until it closes it shares content with each wet face neighbour
  !> that is not closing too: theta (C_n - C_c) min(V_c, V_n) per face, theta =
  !> 1 / (2 ndim + 1) (a closing cell surrounded by material takes the mean of itself and
  !> its neighbours), conservative face by face and computed alike by every block that sees
  !> the face (cq over the padded block less two layers). The block has n interior cells
  !> along each direction and the fractions alpha reach e cells into the halo. The content
  !> cq as it came is left as it is: where a cell closes, the content after the exchange is
  !> put in cn (over the padded block) and relaxed is set; where none does (most blocks, and
  !> every scene without a void body), cn is not touched.
  subroutine relax_closing(lay, offset, n, e, alpha, bigphi, owner, count, cq, cn, tally, &
      relaxed)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), n(3), e(3)
    real(wp), intent(in) :: alpha(1-e(1):, 1-e(2):, 1-e(3):)
    real(wp), intent(in) :: bigphi(:, :, :)   !< the phase's level set over the padded block
    integer, intent(in) :: owner(:, :, :)     !< whose surface (ls_region; 0: a void's)
    logical, intent(in) :: count   !< count the closing cells and their heat in tally
    real(wp), intent(in) :: cq(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)  !< content
    real(wp), allocatable, intent(inout) :: cn(:, :, :, :)
    real(wp), intent(inout) :: tally(2)   !< closing cells (cell-steps), their heat
    logical, intent(out) :: relaxed
    logical, allocatable :: cls(:, :, :)
    real(wp) :: th, vc, vn
    integer :: ii, jj, kk, d, s, nb(3), e2(3)
    logical :: inside
    allocate(cls(1-e(1):n(1)+e(1), 1-e(2):n(2)+e(2), 1-e(3):n(3)+e(3)))
    do kk = 1 - e(3), n(3) + e(3)
      do jj = 1 - e(2), n(2) + e(2)
        do ii = 1 - e(1), n(1) + e(1)
          cls(ii, jj, kk) = closing([ii, jj, kk])
        end do
      end do
    end do
    relaxed = any(cls)
    if (.not. relaxed) return   ! (most blocks, and every scene without a void body)
    e2 = max(e - 1, 0)
    th = 1.0_wp / real(2 * lay%ndim + 1, wp)
    if (allocated(cn)) deallocate(cn)
    allocate(cn(1-lay%ng(1):n(1)+lay%ng(1), 1-lay%ng(2):n(2)+lay%ng(2), &
      1-lay%ng(3):n(3)+lay%ng(3), size(cq, 4)))
    cn = cq
    do kk = 1 - e2(3), n(3) + e2(3)
      do jj = 1 - e2(2), n(2) + e2(2)
        do ii = 1 - e2(1), n(1) + e2(1)
          if (.not. alpha(ii, jj, kk) > 0.0_wp) cycle
          inside = all([ii, jj, kk] >= 1 .and. [ii, jj, kk] <= n)
          if (count .and. cls(ii, jj, kk) .and. inside) tally(1) = tally(1) + 1.0_wp
          do d = 1, lay%ndim
            do s = -1, 1, 2
              nb = [ii, jj, kk]
              nb(d) = nb(d) + s
              if (.not. alpha(nb(1), nb(2), nb(3)) > 0.0_wp) cycle
              if (.not. (cls(ii, jj, kk) .neqv. cls(nb(1), nb(2), nb(3)))) cycle
              vc = cell_volume(lay, offset, ii)
              vn = cell_volume(lay, offset, nb(1))
              cn(ii, jj, kk, :) = cn(ii, jj, kk, :) + th * min(vc, vn) / vc &
                * (cq(nb(1), nb(2), nb(3), :) - cq(ii, jj, kk, :))
            end do
          end do
        end do
      end do
    end do
    if (count) then
      ! the kinetic energy the exchange turned into heat (in the block's own cells)
      do kk = 1, n(3)
        do jj = 1, n(2)
          do ii = 1, n(1)
            tally(2) = tally(2) + (kinetic(cq(ii, jj, kk, :)) &
              - kinetic(cn(ii, jj, kk, :))) * cell_volume(lay, offset, ii)
          end do
        end do
      end do
    end if

  contains

    !> cell c0 closing: wet, its centre outside the phase, and either full by its fraction
    !> or between two cells of the phase along some direction where the level set folds (a
    !> sliver of the void)
    logical function closing(c0)
      integer, intent(in) :: c0(3)
      integer :: g(3), d, m(3), p(3)
      g = c0 + lay%ng
      closing = .false.
      if (.not. alpha(c0(1), c0(2), c0(3)) > 0.0_wp) return
      if (bigphi(g(1), g(2), g(3)) < 0.0_wp .or. owner(g(1), g(2), g(3)) /= 0) return
      closing = .not. alpha(c0(1), c0(2), c0(3)) < full
      if (closing) return
      do d = 1, lay%ndim
        m = g
        p = g
        m(d) = m(d) - 1
        p(d) = p(d) + 1
        ! (a sliver: the level set folds between the two, its second difference below
        ! -h; where a void's flat side passes between cell centres, a centre just outside
        ! between two just inside is no sliver: its second difference is -h^2 / R)
        if (bigphi(m(1), m(2), m(3)) < 0.0_wp .and. bigphi(p(1), p(2), p(3)) < 0.0_wp &
          .and. bigphi(m(1), m(2), m(3)) + bigphi(p(1), p(2), p(3)) &
          - 2.0_wp * bigphi(g(1), g(2), g(3)) < -lay%dx(d)) closing = .true.
      end do
    end function closing
  end subroutine relax_closing

  !> the kinetic energy per volume of content u
  pure real(wp) function kinetic(u)
    real(wp), intent(in) :: u(:)
    kinetic = 0.0_wp
    if (u(i_rho) > 0.0_wp) kinetic = 0.5_wp * sum(u(i_mx:i_mz)**2) / u(i_rho)
  end function kinetic

  !> whether content cc0 at density rho0 (its energy and velocity per mass) has a real,
  !> finite sound speed in equation of state eos
  logical function content_sounds(eos, rho0, cc0) result(sounds)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho0, cc0(:)
    real(wp) :: r1(1), e1(1), p1(1), c21(1)
    sounds = .false.
    if (.not. (rho0 > 0.0_wp .and. cc0(i_rho) > 0.0_wp)) return
    r1 = rho0
    e1 = cc0(i_en) / cc0(i_rho) - 0.5_wp * sum(cc0(i_mx:i_mz)**2) / cc0(i_rho)**2
    call eos_pressure(eos, 1, r1, e1, p1)
    call eos_sound_speed2(eos, 1, r1, p1, c21)
    sounds = c21(1) > 0.0_wp .and. c21(1) <= huge(1.0_wp)
  end function content_sounds

  !> A void body's level set follows the content (manual/theory.md section 7c): in each cut
  !> cell of block blk whose surface is a void body's, the fraction its content fills at
  !> the density of its state, f = C_rho / rho (at most 1; content_rho: the cut phase's mass
  !> content, whose variables start after v0 in q), and the level set's fraction alpha differ
  !> by the drift; the void's level set there moves by gain (f - alpha) h (at most h / 4 a
  !> step), so that the void shrinks as the material fills it. A cell whose centre is in the
  !> void but which the material fills (fraction 1, or content at its state's density or
  !> more) is made the material's at once (theory.md 7d), so that its own state meets its
  !> faces. A material body's own level set is left as it is: its drift shows
  !> in its cut cells only and is harmless there (section 7c); a void's decides when and
  !> where the void closes.
  subroutine cut_follow(blk, ils, v0, ls, alpha, content_rho, gain)
    type(block_t), intent(inout) :: blk
    integer, intent(in) :: ils, v0   !< q's index before the level sets, the phase's
    type(ls_set_t), intent(in) :: ls
    real(wp), intent(in) :: alpha(:, :, :), content_rho(:, :, :), gain
    real(wp), allocatable :: d(:, :, :, :)
    integer :: i, j, k, lv, nl
    real(wp) :: a, f, h, rho, top
    real(wp), parameter :: remnant = 0.01_wp   !< a closed remnant's centre value (cells)
    if (.not. any(ls%kind == ls_void)) return
    h = minval(blk%lay%dx(1:blk%lay%ndim))
    nl = ls%n
    ! each cut cell's move of its void's level set, d (in cells), one array per level set
    allocate(d(0:blk%n(1)+1, 0:blk%n(2)+1, 0:blk%n(3)+1, nl))
    d = 0.0_wp
    do k = 1, blk%n(3)
      do j = 1, blk%n(2)
        do i = 1, blk%n(1)
          a = alpha(i, j, k)
          if (.not. a > 0.0_wp) cycle
          ! the void whose surface this is: the largest -phi over the void bodies
          call lowest_level_set(ls, ls_void, 0, blk%q(i, j, k, ils + 1:ils + nl), lv, top)
          top = -top
          ! (a material body's surface, where one lies nearer than the void's)
          if (any(ls%kind == ls_material .and. blk%q(i, j, k, ils + 1:ils + nl) &
            < -top)) cycle
          rho = blk%q(i, j, k, v0 + i_rho)
          if (.not. a < full .or. (top > 0.0_wp .and. rho > 0.0_wp .and. &
              .not. content_rho(i, j, k) < rho)) then
            ! the material fills the cell (every corner of it in the material, or its
            ! content at its state's density or more), but the void's level set dips below
            ! zero at its centre: a remnant of the void narrower than the cell. The cell is
            ! the material's (its centre made so): as a void cell its state would be a ghost
            ! state and its content, which the fluxes fill, would not push back
            if (top > 0.0_wp) blk%q(i, j, k, ils + lv) = remnant * h
            cycle
          end if
          if (.not. (rho > 0.0_wp .and. content_rho(i, j, k) > 0.0_wp)) cycle
          f = min(content_rho(i, j, k) / rho, 1.0_wp)
          d(i, j, k, lv) = max(-0.25_wp, min(0.25_wp, gain * (f - a)))
        end do
      end do
    end do
    call spread_moves(blk, ils, d)
  end subroutine cut_follow

  !> A material body's level set towards its content, at the step's end (manual/theory.md
  !> section 7c): in each cut cell of the phase p whose surface is a body's (not a void's
  !> that binds it), the fraction its content fills at its state's density, f = C_rho / rho
  !> (not capped: a nearly full cell that holds more moves the surface beyond it), and the
  !> level set's fraction alpha differ by the drift x = f - alpha. Beyond a dead band the
  !> body grows (x > dead) or, beyond six times it, shrinks (x < -6 dead): the drift is
  !> mostly material the level set has not let out, while a shrinking move on a thin sheet
  !> sliding along a wall broke it into cells of alternating sign. The move (at most 1/4 of
  !> a cell a step) is spread as cut_follow's, and the body's level set moves by it times h.
  !> moved: whether any level set moved on this block.
  subroutine cut_follow_body(blk, ils, v0, ls, p, alpha, content_rho, dead, moved)
    type(block_t), intent(inout) :: blk
    integer, intent(in) :: ils, v0, p   !< q's index before the level sets, the phase's; phase
    type(ls_set_t), intent(in) :: ls
    real(wp), intent(in) :: alpha(:, :, :), content_rho(:, :, :), dead
    logical, intent(out) :: moved
    real(wp), allocatable :: d(:, :, :, :)
    integer :: i, j, k, lb, nl
    real(wp) :: a, rho, low, x
    moved = .false.
    if (.not. any(ls%kind == ls_material)) return
    nl = ls%n
    allocate(d(0:blk%n(1)+1, 0:blk%n(2)+1, 0:blk%n(3)+1, nl))
    d = 0.0_wp
    do k = 1, blk%n(3)
      do j = 1, blk%n(2)
        do i = 1, blk%n(1)
          a = alpha(i, j, k)
          if (.not. (a > 0.0_wp .and. a < full)) cycle
          ! the body whose surface this is: the lowest phi over the phase's bodies
          call lowest_level_set(ls, ls_material, p, blk%q(i, j, k, ils + 1:ils + nl), lb, low)
          if (lb == 0) cycle
          ! (a void's surface, where one binds: the region is max(phi_body, -phi_void))
          if (any(ls%kind == ls_void .and. -blk%q(i, j, k, ils + 1:ils + nl) > low)) cycle
          rho = blk%q(i, j, k, v0 + i_rho)
          if (.not. (rho > 0.0_wp .and. content_rho(i, j, k) > 0.0_wp)) cycle
          x = content_rho(i, j, k) / rho - a
          x = max(x - dead, 0.0_wp) + min(x + body_shrink * dead, 0.0_wp)
          d(i, j, k, lb) = max(-0.25_wp, min(0.25_wp, x))
        end do
      end do
    end do
    moved = any(abs(d) > 0.0_wp)
    ! (a body's phi is negative inside: it grows as phi falls)
    if (moved) call spread_moves(blk, ils, -d)
  end subroutine cut_follow_body

  !> Of the level sets of kind `kind` (of phase p as well, where p > 0), the one lowest at a
  !> cell whose level sets are phis: its number l (the first on a tie; 0 where there is none)
  !> and its value low (huge where there is none).
  pure subroutine lowest_level_set(ls, kind, p, phis, l, low)
    type(ls_set_t), intent(in) :: ls
    integer, intent(in) :: kind, p
    real(wp), intent(in) :: phis(:)
    integer, intent(out) :: l
    real(wp), intent(out) :: low
    integer :: m
    l = 0
    low = huge(1.0_wp)
    do m = 1, size(phis)
      if (ls%kind(m) /= kind) cycle
      ! (not one test: Fortran may evaluate both operands, and a set of voids alone may
      ! carry no phases)
      if (p > 0) then
        if (ls%phase(m) /= p) cycle
      end if
      if (phis(m) < low) then
        low = phis(m)
        l = m
      end if
    end do
  end subroutine lowest_level_set

  !> The level sets' moves d (in cells, per level set; zero beyond the block) spread over
  !> each cell's neighbours by the weights (1/4, 1/2, 1/4) along each direction and added to
  !> the level sets times the cell size h. The spreading is the transpose of the averaging
  !> that takes phi to the corners (m_levelset_cut): a move that alternates from cell to cell
  !> changes no corner, so no fraction could ever take it back; pointwise moves fed it and a
  !> void's surface roughened at rest.
  subroutine spread_moves(blk, ils, d)
    type(block_t), intent(inout) :: blk
    integer, intent(in) :: ils
    real(wp), intent(in) :: d(0:, 0:, 0:, :)
    real(wp), parameter :: kernel(-1:1) = [0.25_wp, 0.5_wp, 0.25_wp]
    integer :: i, j, k, l, o1, o2, o3, m(3), r(3)
    real(wp) :: a, w, h
    h = minval(blk%lay%dx(1:blk%lay%ndim))
    r = merge(1, 0, [1, 2, 3] <= blk%lay%ndim)   ! the kernel's reach along each direction
    do l = 1, size(d, 4)
      if (.not. any(abs(d(:, :, :, l)) > 0.0_wp)) cycle
      do k = 1, blk%n(3)
        do j = 1, blk%n(2)
          do i = 1, blk%n(1)
            a = 0.0_wp
            do o3 = -r(3), r(3)
              do o2 = -r(2), r(2)
                do o1 = -1, 1
                  m = [i + o1, j + o2, k + o3]
                  w = kernel(o1)
                  if (r(2) > 0) w = w * kernel(o2)
                  if (r(3) > 0) w = w * kernel(o3)
                  a = a + w * d(m(1), m(2), m(3), l)
                end do
              end do
            end do
            if (abs(a) > 0.0_wp) blk%q(i, j, k, ils + l) = blk%q(i, j, k, ils + l) + a * h
          end do
        end do
      end do
    end do
  end subroutine spread_moves

end module m_gfm_cut_close
