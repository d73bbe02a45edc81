!> The elastic-plastic parts of a cell update (manual/theory.md section 5), and the
!> primitive variables of a row of cells that they and the fluxes start from: the Jaumann
!> stress rates of the right-hand side, the radial return after each Runge-Kutta stage, and
!> the temperature of a solid (the EOS temperature less the elastic and the stored energy).
!> Kernels only: no MPI, no I/O.
module m_elastoplastic
  use m_kinds, only: wp
  use m_eos, only: eos_t, eos_pressure, eos_energy, eos_temperature
  use m_yield, only: strength_t, melt_temperature
  use m_plasticity, only: jaumann_source, radial_return
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, i_sxx, i_syy, i_szz, i_sxy, i_syz, &
    i_sxz, i_epsp, i_wcold
  use m_layout, only: layout_t
  implicit none
  private
  public :: primitive_row, stress_rates, solid_temperature, plastic_correction

contains

  !> Primitive variables (rho, u, v, w, p) of one row of cells i = lo..hi.
  subroutine primitive_row(eos, n, q_rho, q_mx, q_my, q_mz, q_en, rho, u, v, w, p, e)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: q_rho(n), q_mx(n), q_my(n), q_mz(n), q_en(n)
    real(wp), intent(out) :: rho(n), u(n), v(n), w(n), p(n), e(n)
    real(wp) :: rinv
    integer :: i
    do i = 1, n
      rho(i) = q_rho(i)
      rinv = 1.0_wp / q_rho(i)
      u(i) = q_mx(i) * rinv
      v(i) = q_my(i) * rinv
      w(i) = q_mz(i) * rinv
      e(i) = q_en(i) * rinv - 0.5_wp * (u(i)**2 + v(i)**2 + w(i)**2)
    end do
    call eos_pressure(eos, n, rho, e, p)
  end subroutine primitive_row

  !> The non-conservative part of the stress equation (manual/theory.md eq. 5.1):
  !> d(rho S)/dt += rho (2 G D' + W S - S W) (m_plasticity's jaumann_source), with the velocity
  !> gradient L = grad u by central differences; in axisymmetric geometry L_theta theta = u_r / r.
  subroutine stress_rates(lay, st, offset, box, prim, rhs, fraction)
    type(layout_t), intent(in) :: lay
    type(strength_t), intent(in) :: st
    integer, intent(in) :: offset(3)
    integer, intent(in) :: box(2, 3)   !< the cells (low, high corner) whose rates are made
    real(wp), intent(in) :: prim(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(inout) :: rhs(:, :, :, :)
    !> a cut phase's volume fractions: the rates are those of its content (m_gfm_cut)
    real(wp), intent(in), optional :: fraction(:, :, :)
    real(wp) :: l(box(2, 1) - box(1, 1) + 1, 3, 3), h(3)
    real(wp), dimension(box(2, 1) - box(1, 1) + 1, 6) :: sdev, src
    integer :: i, j, k, a, b, c, dir(3), n, i0, i1
    i0 = box(1, 1)
    i1 = box(2, 1)
    n = i1 - i0 + 1
    h = 0.0_wp
    h(1:lay%ndim) = 0.5_wp / lay%dx(1:lay%ndim)
    do k = box(1, 3), box(2, 3)
      do j = box(1, 2), box(2, 2)
        l = 0.0_wp
        do b = 1, lay%ndim
          dir = 0
          dir(b) = 1
          do a = 1, 3
            l(:, a, b) = h(b) * (prim(i0+dir(1):i1+dir(1), j + dir(2), k + dir(3), 1 + a) &
              - prim(i0-dir(1):i1-dir(1), j - dir(2), k - dir(3), 1 + a))
          end do
        end do
        if (lay%axisymmetric) then
          do i = 1, n
            l(i, 3, 3) = prim(i0 + i - 1, j, k, 2) &
              / (lay%lo(1) + (real(offset(1) + i0 + i - 1, wp) - 0.5_wp) * lay%dx(1))
          end do
        end if
        do c = 1, 6
          sdev(:, c) = prim(i0:i1, j, k, i_sxx + c - 1)
        end do
        call jaumann_source(st, n, sdev, l, src)
        if (present(fraction)) then
          do c = 1, 6
            src(:, c) = src(:, c) * fraction(i0:i1, j, k)
          end do
        end if
        do c = 1, 6
          rhs(i0:i1, j, k, i_sxx + c - 1) = rhs(i0:i1, j, k, i_sxx + c - 1) &
            + prim(i0:i1, j, k, i_rho) * src(:, c)
        end do
      end do
    end do
  end subroutine stress_rates

  !> Temperature of a row of solid cells: the EOS temperature of the internal energy less the
  !> elastic energy J2 / (2 G rho) and less the stored cold work w_c (manual/theory.md 5.7).
  subroutine solid_temperature(eos, st, n, rho, e, qrow, temp)
    type(eos_t), intent(in) :: eos
    type(strength_t), intent(in) :: st
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), e(n), qrow(:, :)
    real(wp), intent(out) :: temp(n)
    real(wp) :: eth(n), j2(n)
    j2 = 0.5_wp * (qrow(1:n, i_sxx)**2 + qrow(1:n, i_syy)**2 + qrow(1:n, i_szz)**2) &
      + qrow(1:n, i_sxy)**2 + qrow(1:n, i_syz)**2 + qrow(1:n, i_sxz)**2
    eth = e - qrow(1:n, i_wcold) / rho
    if (st%g > 0.0_wp) eth = eth - j2 / (2.0_wp * st%g * rho**3)
    call eos_temperature(eos, n, rho, eth, temp)
  end subroutine solid_temperature

  !> Radial return after a stage (manual/theory.md section 5): the stage's elastic predictor
  !> is brought back to the yield surface cell by cell. Total energy is untouched: of the
  !> plastic work, the Taylor-Quinney share beta stays in e as heat and 1 - beta is booked as
  !> stored work w_c, which the temperature leaves out.
  !> With level sets, only the phase's real cells are returned (ghost states are rebuilt before
  !> every stage); a cell that has just turned real (fresh) holds a ghost state whose
  !> deviator was built for the flux (the reflected normal stress of MVI) and never loaded
  !> material: it is brought to the yield surface without plastic strain or stored work.
  !> fresh is read only together with isreal.
  subroutine plastic_correction(lay, eos, st, thermal, dt, q, isreal, fresh)
    type(layout_t), intent(in) :: lay
    type(eos_t), intent(in) :: eos
    type(strength_t), intent(in) :: st
    logical, intent(in) :: thermal   !< false: the yield stress sees the reference temperature
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    logical, intent(in), optional :: isreal(:, :, :), fresh(:, :, :)
    real(wp), dimension(lay%bsize(1)) :: rho, u, v, w, p, e, temp, epsp, dwp, epsp0, tmelt
    real(wp) :: sdev(lay%bsize(1), 6)
    integer :: j, k, m, n
    n = lay%bsize(1)
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        if (present(isreal)) then
          ! a row of ghosts and rest states only: nothing to return (void costs nothing)
          if (.not. any(isreal(:, j, k))) cycle
        end if
        call primitive_row(eos, n, q(1:n, j, k, i_rho), q(1:n, j, k, i_mx), &
          q(1:n, j, k, i_my), q(1:n, j, k, i_mz), q(1:n, j, k, i_en), rho, u, v, w, p, e)
        if (thermal) then
          call solid_temperature(eos, st, n, rho, e, q(1:n, j, k, :), temp)
        else
          temp = st%t_ref
        end if
        do m = 1, 6
          sdev(:, m) = q(1:n, j, k, i_sxx + m - 1) / rho
        end do
        epsp = q(1:n, j, k, i_epsp) / rho
        epsp0 = epsp
        if (st%melt_slope > 0.0_wp) then
          tmelt = melt_temperature(st, eos%rho0, rho)
          call radial_return(st, n, sdev, epsp, temp, dt, dwp, tmelt)
        else
          call radial_return(st, n, sdev, epsp, temp, dt, dwp)
        end if
        if (present(fresh)) then
          where (fresh(:, j, k) .or. .not. isreal(:, j, k))
            epsp = epsp0
            dwp = 0.0_wp
          end where
        end if
        do m = 1, 6
          if (present(isreal)) then
            where (isreal(:, j, k)) q(1:n, j, k, i_sxx + m - 1) = rho * sdev(:, m)
          else
            q(1:n, j, k, i_sxx + m - 1) = rho * sdev(:, m)
          end if
        end do
        q(1:n, j, k, i_epsp) = rho * epsp
        q(1:n, j, k, i_wcold) = q(1:n, j, k, i_wcold) + (1.0_wp - st%taylor_quinney) * dwp
      end do
    end do
  end subroutine plastic_correction

end module m_elastoplastic
