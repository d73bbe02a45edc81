!> Unit test of m_eos: round trips e(rho, p) -> p(rho, e), the sound speed against a finite
!> difference of the isentrope (c^2 = dp/drho|_e + p / rho^2 dp/de|_rho), the
!> Mie-Gruneisen pressure on its Hugoniot equal to rho0 Us up, and the Mie-Gruneisen
!> temperature (manual/eos-temperature.md): T on an isentrope integrated here by the
!> trapezoid rule in v, (de/dT)_rho = cv, the Maxwell relation (de/dv)_T = T (dp/dT)_v - p,
!> and the shock temperature against the Walsh-Christian integral along the Hugoniot.
program test_eos
  use m_kinds, only: wp
  use m_eos, only: eos_t, eos_ideal_gas, eos_stiffened_gas, eos_mie_gruneisen, eos_polynomial, &
    eos_pressure, eos_energy, eos_sound_speed2, eos_temperature, eos_prepare
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_error, check_done
  implicit none
  type(eos_t) :: air, water, copper, hmx_poly, copper_unprepared
  call comm_init()
  call check_start('test_eos')
  air = eos_t(kind=eos_ideal_gas, gamma=1.4_wp, cv=717.5_wp)
  water = eos_t(kind=eos_stiffened_gas, gamma=4.4_wp, p_inf=6.0e8_wp, rho0=1000.0_wp)
  copper = eos_t(kind=eos_mie_gruneisen, rho0=8930.0_wp, c0=3940.0_wp, s=1.49_wp, &
    gruneisen=2.0_wp, cv=383.5_wp, T0=298.0_wp)
  call check_eos('air', air, [1.225_wp, 0.01_wp, 50.0_wp], [1.0e5_wp, 1.0_wp, 1.0e9_wp])
  call check_eos('water', water, [1000.0_wp, 1100.0_wp, 990.0_wp], [1.0e5_wp, 1.0e9_wp, 0.0_wp])
  call check_eos('copper', copper, [9000.0_wp, 10000.0_wp, 8500.0_wp], &
    [0.0_wp, 3.0e10_wp, -1.0e9_wp])
  ! section C polynomial HMX: K 12.5 GPa, A 22 GPa, B 15 GPa, gamma 1.03, rho0 1900
  hmx_poly = eos_t(kind=eos_polynomial, rho0=1900.0_wp, gruneisen=1.03_wp, cv=2500.0_wp, &
    T0=298.0_wp, bulk=12.5e9_wp, poly_a=22.0e9_wp, poly_b=15.0e9_wp)
  call check_eos('hmx polynomial', hmx_poly, [2000.0_wp, 2400.0_wp, 1850.0_wp], &
    [1.0e9_wp, 2.0e10_wp, -1.0e8_wp])
  call check_hugoniot()
  call check_beyond_singular()
  copper_unprepared = copper
  call eos_prepare(copper)
  call eos_prepare(hmx_poly)
  call eos_prepare(air)
  call eos_prepare(water)
  call check('no isentrope table for the gases', &
    .not. (allocated(air%isentrope) .or. allocated(water%isentrope)))
  call check_isentrope_temperature('copper', copper)
  call check_isentrope_temperature('hmx polynomial', hmx_poly)
  call check_consistency('copper', copper, [0.8_wp, 1.0_wp, 1.2_wp, 1.4_wp, 1.8_wp])
  call check_consistency('hmx polynomial', hmx_poly, [0.8_wp, 1.0_wp, 1.2_wp, 1.4_wp, 1.8_wp])
  call show_maxwell_residual('copper without eos_prepare (old T0 + (e - e_H)/cv)', &
    copper_unprepared, 1.2_wp, 1000.0_wp)
  call check_shock_temperature()
  call check_table_ends('copper', copper)
  call check_table_ends('hmx polynomial', hmx_poly)
  call check_done()

contains

  subroutine check_eos(name, eos, rho, p)
    character(len=*), intent(in) :: name
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho(:), p(:)
    real(wp) :: e(size(rho)), p2(size(rho)), c2(size(rho))
    real(wp) :: h, pp(1), pm(1), dpdrho, dpde, c2fd, err
    integer :: i
    call eos_energy(eos, size(rho), rho, p, e)
    call eos_pressure(eos, size(rho), rho, e, p2)
    call eos_sound_speed2(eos, size(rho), rho, p, c2)
    do i = 1, size(rho)
      err = abs(p2(i) - p(i)) / max(abs(p(i)), 1.0_wp)
      call check_error(name // ' round trip p(rho, e(rho, p)) = p', err, 1.0e-12_wp)
      h = 1.0e-5_wp * rho(i)
      call eos_pressure(eos, 1, [rho(i) + h], [e(i)], pp)
      call eos_pressure(eos, 1, [rho(i) - h], [e(i)], pm)
      dpdrho = (pp(1) - pm(1)) / (2.0_wp * h)
      h = 1.0e-5_wp * max(abs(e(i)), 1.0_wp)
      call eos_pressure(eos, 1, [rho(i)], [e(i) + h], pp)
      call eos_pressure(eos, 1, [rho(i)], [e(i) - h], pm)
      dpde = (pp(1) - pm(1)) / (2.0_wp * h)
      c2fd = dpdrho + p(i) / rho(i)**2 * dpde
      err = abs(c2(i) - c2fd) / abs(c2fd)
      call check_error(name // ' sound speed against finite difference', err, 1.0e-6_wp)
    end do
  end subroutine check_eos

  !> A shock of particle speed up into copper at rest: Us = c0 + s up, rho = rho0 Us / (Us - up),
  !> e = up^2 / 2, and the pressure must be rho0 Us up.
  subroutine check_hugoniot()
    real(wp) :: up, us, rho(1), e(1), p(1), err
    integer :: k
    do k = 1, 4
      up = 250.0_wp * k**2
      us = copper%c0 + copper%s * up
      rho = copper%rho0 * us / (us - up)
      e = 0.5_wp * up**2
      call eos_pressure(copper, 1, rho, e, p)
      err = abs(p(1) - copper%rho0 * us * up) / (copper%rho0 * us * up)
      call check_error('copper Hugoniot pressure = rho0 Us up', err, 1.0e-12_wp)
    end do
  end subroutine check_hugoniot

  !> The linear Us-up Hugoniot is singular at eta = 1 / s; beyond eta_c = 0.9 / s (where
  !> 1 - s eta = 0.1) p_H goes on as its tangent in eta (theory.md eq. 2.4a). HMX (c0 2801 m/s,
  !> s 2.362, Gamma 1.1): below eta_c the closed form to round-off; across eta_c the pressure
  !> continuous and its slope too; to 3 rho0 (past the singular 1.73 rho0) a finite pressure
  !> and a real sound speed, matching a finite difference, at rest energy and on the Hugoniot.
  subroutine check_beyond_singular()
    type(eos_t) :: hmx
    real(wp) :: eta_c, k0, rho(1), e(1), p(1), c2(1), pl(1), pr(1), err, h, eta, sl, sr
    integer :: m
    character(len=8) :: ratio
    hmx = eos_t(kind=eos_mie_gruneisen, rho0=1900.0_wp, c0=2801.0_wp, s=2.362_wp, &
      gruneisen=1.1_wp, cv=1500.0_wp, T0=298.0_wp)
    k0 = hmx%rho0 * hmx%c0**2
    eta_c = 0.9_wp / hmx%s
    eta = 0.8_wp * eta_c
    rho = hmx%rho0 / (1.0_wp - eta)
    call eos_pressure(hmx, 1, rho, [0.0_wp], p)
    err = abs(p(1) - (k0 * eta / (1.0_wp - hmx%s * eta)**2 &
      - hmx%gruneisen * hmx%rho0 * 0.5_wp * k0 * eta**2 / (1.0_wp - hmx%s * eta)**2 / hmx%rho0)) &
      / abs(p(1))
    call check_error('hmx below eta_c: the Us-up Hugoniot as it was', err, 1.0e-13_wp)
    ! the pressure at e = 0 on each side of eta_c, and its slope in eta from each side
    h = 1.0e-6_wp
    call p_at(hmx, eta_c - h, pl)
    call p_at(hmx, eta_c + h, pr)
    call check_error('hmx p continuous across eta_c', abs(pr(1) - pl(1)) / abs(pl(1)), 1.0e-4_wp)
    call p_at(hmx, eta_c - 2.0_wp * h, p)
    sl = (pl(1) - p(1)) / h
    call p_at(hmx, eta_c + 2.0_wp * h, p)
    sr = (p(1) - pr(1)) / h
    call check_error('hmx dp/deta continuous across eta_c', abs(sr - sl) / abs(sl), 1.0e-3_wp)
    do m = 1, 5
      rho = hmx%rho0 * (1.5_wp + 0.375_wp * (m - 1))
      eta = 1.0_wp - hmx%rho0 / rho(1)
      e = 0.0_wp
      if (mod(m, 2) == 0) then
        call eos_pressure(hmx, 1, rho, e, p)
        e = 0.5_wp * p(1) * eta / hmx%rho0
      end if
      call eos_pressure(hmx, 1, rho, e, p)
      call eos_sound_speed2(hmx, 1, rho, p, c2)
      write(ratio, '(f5.3)') rho(1) / hmx%rho0
      call check('hmx at rho / rho0 = ' // trim(ratio) // ': p finite and c^2 > 0', &
        abs(p(1)) < huge(1.0_wp) .and. c2(1) > 0.0_wp .and. c2(1) < huge(1.0_wp))
      h = 1.0e-7_wp * rho(1)
      call eos_pressure(hmx, 1, rho + h, e, pr)
      call eos_pressure(hmx, 1, rho - h, e, pl)
      sl = (pr(1) - pl(1)) / (2.0_wp * h)
      h = 1.0e3_wp   ! (p is linear in e: a large step, clear of round-off)
      call eos_pressure(hmx, 1, rho, e + h, pr)
      call eos_pressure(hmx, 1, rho, e - h, pl)
      sr = (pr(1) - pl(1)) / (2.0_wp * h)
      err = abs(c2(1) - (sl + p(1) / rho(1)**2 * sr)) / c2(1)
      call check_error('hmx beyond eta_c: sound speed against finite difference', err, 1.0e-5_wp)
    end do
  end subroutine check_beyond_singular

  !> the pressure of eos at e = 0 and eta = 1 - rho0 / rho
  subroutine p_at(eos, eta, p)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: eta
    real(wp), intent(out) :: p(1)
    call eos_pressure(eos, 1, [eos%rho0 / (1.0_wp - eta)], [0.0_wp], p)
  end subroutine p_at

  !> Test (1) and (4): e_s(rho) by the implicit trapezoid rule in v = 1/rho on
  !> de/dv = -p(rho, e) with p linear in e (slope gamma_rho), 10^5 steps from v0; there
  !> T must be T_s(rho): T0 exp(Gamma0 eta) or T0 (rho/rho0)^gamma.
  subroutine check_isentrope_temperature(name, eos)
    character(len=*), intent(in) :: name
    type(eos_t), intent(in) :: eos
    integer, parameter :: nstep = 100000
    real(wp) :: v0, v1, dv, v, e, p_old(1), p_new(1), g_old, g_new, ts, t(1), err, worst
    integer :: k, m
    v0 = 1.0_wp / eos%rho0
    worst = 0.0_wp
    do k = 8, 14
      v1 = v0 / (0.1_wp * k)
      dv = (v1 - v0) / nstep
      e = 0.0_wp
      call eos_pressure(eos, 1, [1.0_wp / v0], [0.0_wp], p_old)
      g_old = gamma_rho(eos, 1.0_wp / v0)
      do m = 1, nstep
        v = v0 + m * dv
        call eos_pressure(eos, 1, [1.0_wp / v], [0.0_wp], p_new)
        g_new = gamma_rho(eos, 1.0_wp / v)
        e = (e * (1.0_wp - 0.5_wp * dv * g_old) - 0.5_wp * dv * (p_old(1) + p_new(1))) &
          / (1.0_wp + 0.5_wp * dv * g_new)
        p_old = p_new
        g_old = g_new
      end do
      call eos_temperature(eos, 1, [1.0_wp / v1], [e], t)
      if (eos%kind == eos_polynomial) then
        ts = eos%T0 * (1.0_wp / (v1 * eos%rho0))**eos%gruneisen
      else
        ts = eos%T0 * exp(eos%gruneisen * (1.0_wp - eos%rho0 * v1))
      end if
      err = abs(t(1) - ts) / ts
      worst = max(worst, err)
      call check_error(name // ' T on the isentrope = T_s(rho)', err, 1.0e-6_wp)
    end do
    write(6, '(a,es9.2)') '  ' // name // ': isentrope T, rho0 0.8-1.4, worst relative error', &
      worst
  end subroutine check_isentrope_temperature

  !> dp/de|_rho of a Mie-Gruneisen kind: Gamma0 rho0, or gamma rho for the polynomial kind.
  pure real(wp) function gamma_rho(eos, rho) result(g)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho
    if (eos%kind == eos_polynomial) then
      g = eos%gruneisen * rho
    else
      g = eos%gruneisen * eos%rho0
    end if
  end function gamma_rho

  !> Test (2): at rho = ratio rho0 and T = 300, 1000, 3000 K, (de/dT)_rho = cv and the
  !> Maxwell relation (de/dv)_T = T (dp/dT)_v - p, by central differences.
  subroutine check_consistency(name, eos, ratio)
    character(len=*), intent(in) :: name
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: ratio(:)
    real(wp), parameter :: temps(3) = [300.0_wp, 1000.0_wp, 3000.0_wp]
    real(wp) :: rho, e, de, tp(1), tm(1), cvfd, err, worst_cv, worst_maxwell
    integer :: i, k
    worst_cv = 0.0_wp
    worst_maxwell = 0.0_wp
    do i = 1, size(ratio)
      do k = 1, size(temps)
        rho = ratio(i) * eos%rho0
        e = energy_at(eos, rho, temps(k))
        de = 1.0e-4_wp * eos%cv * temps(k)
        call eos_temperature(eos, 1, [rho], [e + de], tp)
        call eos_temperature(eos, 1, [rho], [e - de], tm)
        cvfd = 2.0_wp * de / (tp(1) - tm(1))
        err = abs(cvfd - eos%cv) / eos%cv
        worst_cv = max(worst_cv, err)
        call check_error(name // ' (de/dT)_rho = cv', err, 1.0e-8_wp)
        err = maxwell_residual(eos, rho, temps(k))
        worst_maxwell = max(worst_maxwell, err)
        call check_error(name // ' (de/dv)_T = T (dp/dT)_v - p', err, 1.0e-7_wp)
      end do
    end do
    write(6, '(a,es9.2,a,es9.2)') '  ' // name // ': worst (de/dT)_rho/cv - 1', worst_cv, &
      ', worst Maxwell residual', worst_maxwell
  end subroutine check_consistency

  !> e(rho, T) by two secant steps on T(rho, e) (T is linear in e, so the second is a check).
  real(wp) function energy_at(eos, rho, temp) result(e)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho, temp
    real(wp) :: t(1)
    integer :: it
    e = 0.0_wp
    do it = 1, 2
      call eos_temperature(eos, 1, [rho], [e], t)
      e = e + eos%cv * (temp - t(1))
    end do
  end function energy_at

  !> |(de/dv)_T - T (dp/dT)_v + p| / (|p| + |T (dp/dT)_v|) at (rho, temp).
  real(wp) function maxwell_residual(eos, rho, temp) result(r)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho, temp
    real(wp) :: v, hv, ht, dedv, dpdt, p(1), pp(1), pm(1)
    v = 1.0_wp / rho
    hv = 1.0e-5_wp * v
    ht = 1.0e-3_wp * temp
    dedv = (energy_at(eos, 1.0_wp / (v + hv), temp) - energy_at(eos, 1.0_wp / (v - hv), temp)) &
      / (2.0_wp * hv)
    call eos_pressure(eos, 1, [rho], [energy_at(eos, rho, temp + ht)], pp)
    call eos_pressure(eos, 1, [rho], [energy_at(eos, rho, temp - ht)], pm)
    call eos_pressure(eos, 1, [rho], [energy_at(eos, rho, temp)], p)
    dpdt = (pp(1) - pm(1)) / (2.0_wp * ht)
    r = abs(dedv - temp * dpdt + p(1)) / (abs(p(1)) + abs(temp * dpdt))
  end function maxwell_residual

  subroutine show_maxwell_residual(name, eos, ratio, temp)
    character(len=*), intent(in) :: name
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: ratio, temp
    write(6, '(a,f4.2,a,f6.0,a,es9.2,a)') '  ' // name // ' at rho/rho0 ', ratio, ', T ', temp, &
      ' K: Maxwell residual ', maxwell_residual(eos, ratio * eos%rho0, temp), ' (not checked)'
  end subroutine show_maxwell_residual

  !> Test (3): copper shocked from rest at (rho0, T0) to up = 1000 m/s. On the Hugoniot
  !> T dS = (1/2)((V0 - V) dp_H + p_H dV) and T dS = cv dT + cv T Gamma0 rho0 dV, so
  !> T_H = exp(Gamma0 eta) (T0 + (c0^2 s / cv) int_0^eta exp(-Gamma0 x) x^2 / (1 - s x)^3 dx)
  !> (Walsh and Christian 1955; manual/eos-temperature.md eq. 2.14), evaluated here by
  !> Simpson's rule; it never uses e_s.
  subroutine check_shock_temperature()
    integer, parameter :: nsimpson = 20000
    real(wp) :: up, us, eta, rho(1), e(1), p(1), t(1), tw, h, x, w, integral
    integer :: k, m
    do k = 1, 4
      up = 500.0_wp * k
      us = copper%c0 + copper%s * up
      eta = up / us
      rho = copper%rho0 * us / (us - up)
      e = 0.5_wp * up**2
      call eos_pressure(copper, 1, rho, e, p)
      call eos_temperature(copper, 1, rho, e, t)
      h = eta / nsimpson
      integral = 0.0_wp
      do m = 0, nsimpson
        x = m * h
        w = merge(1.0_wp, merge(4.0_wp, 2.0_wp, mod(m, 2) == 1), m == 0 .or. m == nsimpson)
        integral = integral + w * exp(-copper%gruneisen * x) * x**2 / (1.0_wp - copper%s * x)**3
      end do
      integral = integral * h / 3.0_wp
      tw = exp(copper%gruneisen * eta) * (copper%T0 + copper%c0**2 * copper%s / copper%cv &
        * integral)
      write(6, '(a,f6.0,a,f6.1,a,f8.2,a,f8.2,a,es9.2)') '  copper shock up ', up, &
        ' m/s, p ', p(1) / 1.0e9_wp, ' GPa: T ', t(1), ' K, Walsh-Christian ', tw, &
        ' K, relative difference ', abs(t(1) - tw) / tw
      call check_error('copper shock temperature = Walsh-Christian integral', &
        abs(t(1) - tw) / tw, 1.0e-8_wp)
      if (k == 2) call check('copper at up = 1000 m/s at least 100 K above T0', &
        t(1) >= copper%T0 + 100.0_wp)
    end do
  end subroutine check_shock_temperature

  !> Outside the table e_s is extrapolated linearly: T must be continuous across both table
  !> ends (the change over eta_end + d minus that over eta_end - d, O(d^2 T'') if T is
  !> continuous, d = 1e-7), and far states (rho0 / 3, 3 rho0) must give finite T.
  subroutine check_table_ends(name, eos)
    character(len=*), intent(in) :: name
    type(eos_t), intent(in) :: eos
    real(wp), parameter :: d = 1.0e-7_wp
    real(wp) :: eta_end(2), rho(3), t(3), far(2), jump
    integer :: k
    eta_end = [lbound(eos%isentrope, 2), ubound(eos%isentrope, 2)] * 1.0e-3_wp
    do k = 1, 2
      rho = eos%rho0 / (1.0_wp - (eta_end(k) + [-3.0_wp * d, -d, d]))
      call eos_temperature(eos, 3, rho, [1.0e5_wp, 1.0e5_wp, 1.0e5_wp], t)
      jump = (t(3) - t(2)) - (t(2) - t(1))
      call check_error(name // ' T continuous at a table end', abs(jump), 1.0e-6_wp)
    end do
    call eos_temperature(eos, 2, [eos%rho0 / 3.0_wp, 3.0_wp * eos%rho0], [1.0e5_wp, 1.0e5_wp], &
      far)
    call check(name // ' T finite outside the table', all(abs(far) < huge(1.0_wp)))
  end subroutine check_table_ends

end program test_eos
