!> Unit test of m_yield and m_plasticity: the radial return lands on the yield surface and
!> solves the consistency condition for every model (Johnson-Cook metals of published-data
!> section A at several temperatures, rates and strains, the power laws of section C),
!> linear-hardening consistency against the closed form, objectivity of the Jaumann rate
!> under a rigid quarter turn, the Jaumann source against matrix products, J1 = 0 after the
!> return, melt, plastic work, the elastic range, and the material_t conversion.
!> Each check prints its largest error and its tolerance.
program test_strength
  use m_kinds, only: wp, i8
  use m_config, only: material_t
  use m_yield, only: strength_t, strength_from_material, strength_model_from_name, &
    strength_problem, yield_stress, strength_none, strength_elastic, &
    strength_perfectly_plastic, strength_linear_hardening, strength_johnson_cook, &
    strength_viscoplastic, melt_temperature
  use m_plasticity, only: radial_return, von_mises, jaumann_source
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check_error, check_done
  implicit none
  integer, parameter :: npts = 16
  real(wp), parameter :: pi = 3.14159265358979323846_wp
  type(strength_t) :: copper, tungsten, hh_steel, aluminium, mild_steel
  type(strength_t) :: al_piston, cu_taylor, hmx, htpb, interface_law, hmx_threshold
  integer(i8) :: seed
  real(wp) :: group_err(4)   !< worst errors of a group of returns, see summary
  call comm_init()
  call check_start('test_strength', show_passes=.true.)
  seed = 20240611_i8
  group_err = [0.0_wp, 0.0_wp, 0.0_wp, huge(1.0_wp)]
  call make_materials()

  write(6, '(a)') '1. return lands on the yield surface and solves the consistency condition'
  call check_jc_family('copper JC', copper)
  call check_jc_family('tungsten JC', tungsten)
  call check_jc_family('high-hard steel JC', hh_steel)
  call check_jc_family('aluminium JC', aluminium)
  call check_jc_family('mild steel JC', mild_steel)
  call check_return('aluminium perfectly plastic', al_piston, 300.0_wp, 1.0e-8_wp, 0.0_wp, 0.0_wp)
  call check_return('aluminium perfectly plastic eps_p=0.3', al_piston, 300.0_wp, 1.0e-8_wp, &
    0.3_wp, 0.0_wp)
  call check_return('copper linear hardening', cu_taylor, 300.0_wp, 1.0e-8_wp, 0.0_wp, 0.0_wp)
  call check_return('copper linear hardening eps_p=2', cu_taylor, 300.0_wp, 1.0e-8_wp, 2.0_wp, &
    0.0_wp)
  call check_power_law('HMX power law', hmx, 20.0e6_wp)
  call check_power_law('HTPB power law', htpb, 0.2e6_wp)
  call check_power_law('HMX-HTPB interface power law', interface_law, 0.2e6_wp)
  call check_power_law('HMX power law + 370 MPa threshold', hmx_threshold, 0.0_wp)

  write(6, '(a)') '2. linear-hardening consistency'
  call check_linear_hardening()

  write(6, '(a)') '3. objectivity and the Jaumann source'
  call check_rigid_rotation()
  call check_jaumann_matrix()

  write(6, '(a)') '4. J1 = trace(S) after the return'
  call check_trace()

  write(6, '(a)') '5. melt'
  call check_melt()
  call check_melt_rising()

  write(6, '(a)') '6. plastic work'
  call check_plastic_work()

  write(6, '(a)') '7. elastic range, model names, material_t defaults'
  call check_elastic_range()
  call check_from_material()

  call check_done()

contains

  subroutine make_materials()
    real(wp) :: g_hmx, g_htpb
    ! section A Johnson-Cook sets, T_ref 298 K, eps_rate0 1/s
    copper = jc(0.40e9_wp, 0.177e9_wp, 1.0_wp, 0.025_wp, 1.09_wp, 43.33e9_wp, 1358.0_wp)
    tungsten = jc(1.51e9_wp, 0.177e9_wp, 0.12_wp, 0.016_wp, 1.0_wp, 124.0e9_wp, 1777.0_wp)
    hh_steel = jc(1.50e9_wp, 0.569e9_wp, 0.22_wp, 0.003_wp, 1.17_wp, 77.3e9_wp, 1723.0_wp)
    aluminium = jc(0.324e9_wp, 0.114e9_wp, 0.42_wp, 0.002_wp, 1.34_wp, 26.0e9_wp, 925.0_wp)
    mild_steel = jc(0.53e9_wp, 0.229e9_wp, 0.302_wp, 0.027_wp, 1.0_wp, 81.8e9_wp, 1836.0_wp)
    ! the piston aluminium of issue 3 and the Taylor-bar copper of section D
    al_piston = strength_from_material(material_t(strength_model='perfectly_plastic', &
      shear_modulus=28.6e9_wp, yield0=0.26e9_wp))
    cu_taylor = strength_from_material(material_t(strength_model='linear_hardening', &
      shear_modulus=117.0e9_wp / (2.0_wp * 1.35_wp), yield0=400.0e6_wp, &
      hardening_modulus=100.0e6_wp))
    ! section C power laws; G = E / (2 (1 + nu)) from the same table
    g_hmx = 14240.0e6_wp / (2.0_wp * 1.31_wp)
    g_htpb = 2.5e6_wp / (2.0_wp * 1.45_wp)
    hmx = power_law(1.08_wp, -0.79_wp, 1.58_wp, g_hmx, 0.0_wp)
    htpb = power_law(0.54_wp, -0.18_wp, 1.78_wp, g_htpb, 0.0_wp)
    interface_law = power_law(1.59_wp, -0.87_wp, 1.88_wp, g_htpb, 0.0_wp)
    hmx_threshold = power_law(1.08_wp, -0.79_wp, 1.58_wp, 7.2e9_wp, 370.0e6_wp)
  end subroutine make_materials

  function jc(a, b, n, c, m, g, t_melt) result(st)
    real(wp), intent(in) :: a, b, n, c, m, g, t_melt
    type(strength_t) :: st
    st = strength_from_material(material_t(strength_model='johnson_cook', shear_modulus=g, &
      yield0=a, jc_b=b, jc_n=n, jc_c=c, jc_m=m, t_melt=t_melt, eps_rate0=1.0_wp))
  end function jc

  function power_law(chi, m, n, g, y0) result(st)
    real(wp), intent(in) :: chi, m, n, g, y0
    type(strength_t) :: st
    st = strength_from_material(material_t(strength_model='viscoplastic_power_law', &
      shear_modulus=g, vp_chi=chi, vp_m=m, vp_n=n, yield0=y0))
  end function power_law

  !> Johnson-Cook at three temperatures (room, warm, 50 K below melt), three time steps
  !> (plastic rates from about 1 /s to 1e7 /s, across the eps_rate0 kink) and three strains.
  subroutine check_jc_family(name, st)
    character(len=*), intent(in) :: name
    type(strength_t), intent(in) :: st
    real(wp) :: temps(3), dts(3), strains(3)
    integer :: a, b, c
    character(len=128) :: label
    temps = [298.0_wp, 0.5_wp * (298.0_wp + st%t_melt), st%t_melt - 50.0_wp]
    dts = [1.0e-9_wp, 1.0e-6_wp, 1.0e-2_wp]
    strains = [0.0_wp, 0.05_wp, 1.0_wp]
    do a = 1, 3
      do b = 1, 3
        do c = 1, 3
          write(label, '(a,a,f0.0,a,es7.1,a,f0.2)') name, ' T=', temps(a), ' dt=', dts(b), &
            ' eps_p=', strains(c)
          call check_return(trim(label), st, temps(a), dts(b), strains(c), 0.0_wp, quiet=.true.)
        end do
      end do
    end do
    call summary(name // ' (27 states of T, rate, eps_p)')
  end subroutine check_jc_family

  subroutine check_power_law(name, st, scale)
    character(len=*), intent(in) :: name
    type(strength_t), intent(in) :: st
    real(wp), intent(in) :: scale
    real(wp) :: dts(4)
    integer :: b
    character(len=128) :: label
    dts = [1.0e-9_wp, 1.0e-6_wp, 1.0e-3_wp, 1.0_wp]
    do b = 1, 4
      write(label, '(a,a,es7.1)') name, ' dt=', dts(b)
      call check_return(trim(label), st, 300.0_wp, dts(b), 0.0_wp, scale, quiet=.true.)
    end do
    call summary(name // ' (dt 1e-9 .. 1 s)')
  end subroutine check_power_law

  ! Largest errors of a group of check_return calls (reset by summary).
  subroutine summary(name)
    character(len=*), intent(in) :: name
    call check_error(name // ': on surface', group_err(1), 1.0e-12_wp)
    call check_error(name // ': consistency residual / allowed', group_err(2), 1.0_wp)
    call check_error(name // ': radial direction', group_err(3), 1.0e-12_wp)
    call check_error(name // ': dwp >= 0 (min dwp / (sigma_y d))', -group_err(4), 0.0_wp, &
      shown=group_err(4))
    group_err = 0.0_wp
    group_err(4) = huge(1.0_wp)
  end subroutine summary

  !> npts random trial states, 1.5 to 20 times the static yield stress (or `scale` when that
  !> is 0), with a random trace; after the return sigma_eq = sigma_y(eps_p, d / dt, T), the
  !> consistency sigma_trial - 3 G d = sigma_eq holds, S stays parallel to the trial deviator
  !> and dwp >= 0.
  subroutine check_return(name, st, temp, dt, eps0, scale, quiet)
    character(len=*), intent(in) :: name
    type(strength_t), intent(in) :: st
    real(wp), intent(in) :: temp, dt, eps0, scale
    logical, intent(in), optional :: quiet
    real(wp) :: s(npts, 6), dev(npts, 6), eps_p(npts), temps(npts), dwp(npts)
    real(wp) :: sig_trial(npts), seq(npts), ref, d, sy, err(4)
    integer :: i
    ref = yield_stress(st, eps0, 0.0_wp, temp)
    if (.not. ref > 0.0_wp) ref = scale
    call random_trials(npts, ref, 1.5_wp, 20.0_wp, 1.0_wp, s, dev, sig_trial)
    eps_p = eps0
    temps = temp
    call radial_return(st, npts, s, eps_p, temps, dt, dwp)
    call von_mises(npts, s, seq)
    err = [0.0_wp, 0.0_wp, 0.0_wp, huge(1.0_wp)]
    do i = 1, npts
      d = eps_p(i) - eps0
      sy = yield_stress(st, eps_p(i), d / dt, temp)
      err(1) = max(err(1), abs(seq(i) - sy) / sy)
      ! the residual against what the terms can resolve: 1e-12 sigma_y, the rounding of
      ! sigma_trial - 3 G d when the stress relaxes to sigma_y << sigma_trial, and the last
      ! bit of the stored eps_p (which is all the caller keeps of d)
      err(2) = max(err(2), abs(sig_trial(i) - 3.0_wp * st%g * d - sy) / (1.0e-12_wp * sy &
        + 8.0_wp * epsilon(1.0_wp) * sig_trial(i) + 3.0_wp * st%g * spacing(eps_p(i))))
      err(3) = max(err(3), maxval(abs(s(i, :) - sy / sig_trial(i) * dev(i, :))) / sy)
      err(4) = min(err(4), dwp(i) / (sy * d))
    end do
    group_err(1:3) = max(group_err(1:3), err(1:3))
    group_err(4) = min(group_err(4), err(4))
    if (present(quiet)) then
      if (quiet) return
    end if
    call summary(name)
  end subroutine check_return

  !> Linear hardening: sigma_eq = Y0 + H eps_p after the return and
  !> d = (sigma_trial - Y0 - H eps_p0) / (3 G + H), at several starting strains.
  subroutine check_linear_hardening()
    real(wp) :: s(npts, 6), dev(npts, 6), eps_p(npts), temps(npts), dwp(npts)
    real(wp) :: sig_trial(npts), seq(npts), eps0, y_old, d_exact, e_surf, e_d
    integer :: k, i
    e_surf = 0.0_wp
    e_d = 0.0_wp
    temps = 300.0_wp
    do k = 0, 4
      eps0 = 0.5_wp * k
      y_old = cu_taylor%y0 + cu_taylor%h * eps0
      call random_trials(npts, y_old, 1.01_wp, 30.0_wp, 0.3_wp, s, dev, sig_trial)
      eps_p = eps0
      call radial_return(cu_taylor, npts, s, eps_p, temps, 1.0e-7_wp, dwp)
      call von_mises(npts, s, seq)
      do i = 1, npts
        e_surf = max(e_surf, abs(seq(i) - (cu_taylor%y0 + cu_taylor%h * eps_p(i))) / seq(i))
        d_exact = (sig_trial(i) - y_old) / (3.0_wp * cu_taylor%g + cu_taylor%h)
        e_d = max(e_d, abs((eps_p(i) - eps0) - d_exact) / d_exact)
      end do
    end do
    call check_error('copper Taylor bar: sigma_eq = Y0 + H eps_p after the return', e_surf, &
      1.0e-12_wp)
    call check_error('copper Taylor bar: d eps_p = (sigma_trial - sigma_y0) / (3G + H)', e_d, &
      1.0e-12_wp)
  end subroutine check_linear_hardening

  !> A stressed copper element spun as a rigid body about the axis (1, 2, 3) for a quarter
  !> turn: dS/dt = W S - S W by RK4; J2 is kept and S ends as R S0 R^T (Rodrigues).
  subroutine check_rigid_rotation()
    integer, parameter :: nsteps(2) = [100, 1000]
    real(wp) :: s0(1, 6), s(1, 6), k1(1, 6), k2(1, 6), k3(1, 6), k4(1, 6), l(1, 3, 3)
    real(wp) :: axis(3), omega, h, j2_0, j2, rot(3, 3), kmat(3, 3), m0(3, 3), m1(3, 3)
    real(wp) :: err_j2, err_s
    integer :: step, run
    character(len=128) :: label
    s0(1, :) = [120.0e6_wp, -50.0e6_wp, -70.0e6_wp, 80.0e6_wp, -30.0e6_wp, 45.0e6_wp]
    omega = 2.0e5_wp
    axis = [1.0_wp, 2.0_wp, 3.0_wp] / sqrt(14.0_wp)
    kmat = reshape([0.0_wp, axis(3), -axis(2), -axis(3), 0.0_wp, axis(1), &
      axis(2), -axis(1), 0.0_wp], [3, 3])
    l(1, :, :) = omega * kmat   ! u = omega x r: l_ij = du_i/dx_j, pure spin
    j2_0 = second_invariant(s0(1, :))
    do run = 1, 2
      h = 0.5_wp * pi / omega / nsteps(run)
      s = s0
      do step = 1, nsteps(run)
        call jaumann_source(copper, 1, s, l, k1)
        call jaumann_source(copper, 1, s + 0.5_wp * h * k1, l, k2)
        call jaumann_source(copper, 1, s + 0.5_wp * h * k2, l, k3)
        call jaumann_source(copper, 1, s + h * k3, l, k4)
        s = s + h / 6.0_wp * (k1 + 2.0_wp * k2 + 2.0_wp * k3 + k4)
      end do
      j2 = second_invariant(s(1, :))
      err_j2 = abs(j2 - j2_0) / j2_0
      rot = identity() + kmat + matmul(kmat, kmat)   ! quarter turn: sin = 1, 1 - cos = 1
      m0 = to_matrix(s0(1, :))
      m1 = matmul(rot, matmul(m0, transpose(rot)))
      err_s = maxval(abs(to_matrix(s(1, :)) - m1)) / maxval(abs(m0))
      write(label, '(a,i0,a)') 'rigid quarter turn, RK4 ', nsteps(run), ' steps'
      if (run == 1) then
        write(6, '(a,es9.2,a,es9.2,a)') '  info ' // trim(label) // ': J2 error ', err_j2, &
          ', stress error ', err_s, ' (coarse run, not checked)'
      else
        call check_error(trim(label) // ': J2 kept', err_j2, 1.0e-10_wp)
        call check_error(trim(label) // ': S = R S0 R^T', err_s, 1.0e-10_wp)
      end if
    end do
  end subroutine check_rigid_rotation

  !> jaumann_source against 2 G D' + W S - S W built by matrix products, for random L and S
  !> (every component of L set, as in 3D, and the hoop L_33 of axisymmetric runs).
  subroutine check_jaumann_matrix()
    real(wp) :: s(npts, 6), l(npts, 3, 3), src(npts, 6)
    real(wp) :: lm(3, 3), dm(3, 3), wm(3, 3), sm(3, 3), ref(3, 3), err, scale, row(6)
    integer :: i, a, b
    do i = 1, npts
      do a = 1, 6
        s(i, a) = 1.0e8_wp * (2.0_wp * uniform() - 1.0_wp)
      end do
      do b = 1, 3
        do a = 1, 3
          l(i, a, b) = 1.0e4_wp * (2.0_wp * uniform() - 1.0_wp)
        end do
      end do
    end do
    call jaumann_source(copper, npts, s, l, src)
    err = 0.0_wp
    do i = 1, npts
      lm = l(i, :, :)
      dm = 0.5_wp * (lm + transpose(lm))
      dm = dm - (dm(1, 1) + dm(2, 2) + dm(3, 3)) / 3.0_wp * identity()
      wm = 0.5_wp * (lm - transpose(lm))
      row = s(i, :)
      sm = to_matrix(row)
      ref = 2.0_wp * copper%g * dm + matmul(wm, sm) - matmul(sm, wm)
      scale = maxval(abs(ref))
      row = src(i, :)
      err = max(err, maxval(abs(to_matrix(row) - ref)) / scale)
    end do
    call check_error('jaumann_source = 2 G D'' + W S - S W (random L, S)', err, 1.0e-14_wp)
  end subroutine check_jaumann_matrix

  !> Trial states with a trace 1, 1e3 and 1e6 times their deviator: after the return
  !> |trace| <= 1e-14 |S| (Frobenius), for points inside and outside the surface.
  subroutine check_trace()
    real(wp) :: s(npts, 6), dev(npts, 6), eps_p(npts), temps(npts), dwp(npts), sig(npts)
    real(wp) :: err, trace_scale(3), frob
    integer :: k, i
    trace_scale = [1.0_wp, 1.0e3_wp, 1.0e6_wp]
    temps = 300.0_wp
    err = 0.0_wp
    do k = 1, 3
      call random_trials(npts, copper%y0, 0.2_wp, 20.0_wp, trace_scale(k), s, dev, sig)
      eps_p = 0.1_wp
      call radial_return(copper, npts, s, eps_p, temps, 1.0e-6_wp, dwp)
      do i = 1, npts
        frob = sqrt(sum(s(i, 1:3)**2) + 2.0_wp * sum(s(i, 4:6)**2))
        err = max(err, abs(s(i, 1) + s(i, 2) + s(i, 3)) / frob)
      end do
    end do
    call check_error('trace(S) / |S| after the return (trial trace up to 1e6 |S|)', err, 1.0e-14_wp)
  end subroutine check_trace

  !> Copper Johnson-Cook: sigma_y = 0 at and above T_melt, and the return then gives S = 0
  !> exactly with dwp = 0; below melt (1 mK and 58 K below) strength stays positive.
  subroutine check_melt()
    integer, parameter :: nt = 4
    real(wp) :: temps(nt), s(nt, 6), dev(nt, 6), sig(nt), eps_p(nt), dwp(nt), y(nt)
    real(wp) :: err
    temps = [1358.0_wp, 1500.0_wp, 1357.999_wp, 1300.0_wp]
    y = yield_stress(copper, 0.2_wp, 1.0e4_wp, temps)
    call check_error('JC copper sigma_y at T = T_melt and above (must be 0)', maxval(abs(y(1:2))), &
      0.0_wp)
    call check_error('JC copper sigma_y below melt positive (-min sigma_y)', -minval(y(3:4)), &
      0.0_wp, shown=minval(y(3:4)))
    call random_trials(nt, copper%y0, 2.0_wp, 5.0_wp, 1.0_wp, s, dev, sig)
    eps_p = 0.2_wp
    call radial_return(copper, nt, s, eps_p, temps, 1.0e-7_wp, dwp)
    err = maxval(abs(s(1:2, :)))
    call check_error('JC copper return at and above melt: max |S| (must be 0)', err, 0.0_wp)
    call check_error('JC copper return at and above melt: dwp (must be 0)', maxval(abs(dwp(1:2))), &
      0.0_wp)
    call von_mises(nt, s, sig)
    call check_error('JC copper return below melt: -min sigma_eq', -minval(sig(3:4)), 0.0_wp, &
      shown=minval(sig(3:4)))
  end subroutine check_melt

  !> A melt point rising with compression (Kraut-Kennedy, melt_temperature): HMX's 550 K with
  !> the slope 1.53 gives 550 (1 + 1.53 (1 - 1900/2200)) = 664.77 K at 2200 kg/m3, 550 K at
  !> rho0, and the floor 275 K when stretched far; a return given these points' melt
  !> temperatures removes the strength of a point at 600 K and rho0 (above its 550 K) and
  !> keeps that of a point at 600 K and 2200 kg/m3 (below its 664.77 K), as the same return with
  !> the constant t_melt of each point does.
  subroutine check_melt_rising()
    integer, parameter :: nt = 4
    type(strength_t) :: st, one
    real(wp) :: rho(nt), tm(nt), temps(nt), s(nt, 6), s1(nt, 6), dev(nt, 6), sig(nt)
    real(wp) :: eps_p(nt), eps1(nt), dwp(nt), dwp1(nt), err
    integer :: i
    st = strength_from_material(material_t(name='hmx', strength_model='perfectly_plastic', &
      shear_modulus=12.0e9_wp, yield0=0.26e9_wp, t_melt=550.0_wp, melt_slope=1.53_wp))
    rho = [1900.0_wp, 2200.0_wp, 2200.0_wp, 100.0_wp]
    tm = melt_temperature(st, 1900.0_wp, rho)
    err = maxval(abs(tm - [550.0_wp, 550.0_wp * (1.0_wp + 1.53_wp * (1.0_wp - 1900.0_wp / &
      2200.0_wp)), 550.0_wp * (1.0_wp + 1.53_wp * (1.0_wp - 1900.0_wp / 2200.0_wp)), 275.0_wp]))
    call check_error('Kraut-Kennedy melt temperature at rho0, 2200, 2200, 100 kg/m3 (K)', err, &
      1.0e-12_wp)
    temps = [600.0_wp, 600.0_wp, 700.0_wp, 300.0_wp]
    call random_trials(nt, st%y0, 2.0_wp, 5.0_wp, 1.0_wp, s, dev, sig)
    s1 = s
    eps_p = 0.1_wp
    eps1 = eps_p
    call radial_return(st, nt, s, eps_p, temps, 1.0e-9_wp, dwp, tm)
    err = 0.0_wp
    do i = 1, nt
      one = st
      one%t_melt = tm(i)
      call radial_return(one, 1, s1(i:i, :), eps1(i:i), temps(i:i), 1.0e-9_wp, dwp1(i:i))
      err = max(err, maxval(abs(s(i, :) - s1(i, :))), abs(dwp(i) - dwp1(i)))
    end do
    call check_error('return with per-point melt = return with each constant melt', err, 0.0_wp)
    call von_mises(nt, s, sig)
    call check_error('rising melt: above its melt (600 K at rho0, 700 K at 2200) no strength', &
      max(sig(1), sig(3)), 0.0_wp)
    call check_error('rising melt: below its melt (600 K at 2200 kg/m3) on the yield surface', &
      abs(sig(2) - st%y0) / st%y0, 1.0e-12_wp)
  end subroutine check_melt_rising

  !> dwp >= 0 everywhere (checked in 1.) and, for linear hardening, equal to the dissipation
  !> (Y0 + H (eps_p0 + d / 2)) d, the midpoint yield times the increment.
  subroutine check_plastic_work()
    real(wp) :: s(npts, 6), dev(npts, 6), eps_p(npts), temps(npts), dwp(npts), sig(npts)
    real(wp) :: eps0, d, w, err, wmin
    integer :: k, i
    temps = 300.0_wp
    err = 0.0_wp
    wmin = huge(1.0_wp)
    do k = 0, 3
      eps0 = 0.7_wp * k
      call random_trials(npts, cu_taylor%y0 + cu_taylor%h * eps0, 0.5_wp, 30.0_wp, 1.0_wp, &
        s, dev, sig)
      eps_p = eps0
      call radial_return(cu_taylor, npts, s, eps_p, temps, 1.0e-7_wp, dwp)
      do i = 1, npts
        d = eps_p(i) - eps0
        w = (cu_taylor%y0 + cu_taylor%h * (eps0 + 0.5_wp * d)) * d
        wmin = min(wmin, dwp(i))
        if (d > 0.0_wp) err = max(err, abs(dwp(i) - w) / w)
        if (.not. d > 0.0_wp) err = max(err, abs(dwp(i)))
      end do
    end do
    call check_error('linear hardening dwp = midpoint sigma_y d eps_p', err, 1.0e-10_wp)
    call check_error('linear hardening dwp >= 0 (-min dwp)', -wmin, 0.0_wp, shown=wmin)
  end subroutine check_plastic_work

  !> Inside the surface nothing changes but the trace; an elastic material never yields.
  subroutine check_elastic_range()
    real(wp) :: s(npts, 6), dev(npts, 6), eps_p(npts), temps(npts), dwp(npts), sig(npts)
    real(wp) :: err
    type(strength_t) :: elastic
    temps = 500.0_wp
    call random_trials(npts, yield_stress(copper, 0.1_wp, 0.0_wp, 500.0_wp), 0.01_wp, &
      0.99_wp, 1.0_wp, s, dev, sig)
    eps_p = 0.1_wp
    call radial_return(copper, npts, s, eps_p, temps, 1.0e-6_wp, dwp)
    err = maxval(abs(s - dev)) / maxval(abs(dev)) + maxval(abs(eps_p - 0.1_wp)) &
      + maxval(abs(dwp))
    call check_error('JC copper inside the surface: S, eps_p, dwp unchanged', err, 1.0e-15_wp)
    elastic = strength_from_material(material_t(strength_model='elastic', &
      shear_modulus=0.27e9_wp))
    call random_trials(npts, 1.0e9_wp, 1.0_wp, 1.0e3_wp, 1.0_wp, s, dev, sig)
    eps_p = 0.0_wp
    call radial_return(elastic, npts, s, eps_p, temps, 1.0e-6_wp, dwp)
    err = maxval(abs(s - dev)) / maxval(abs(dev)) + maxval(abs(eps_p)) + maxval(abs(dwp))
    call check_error('elastic binder at 1 TPa: S, eps_p, dwp unchanged', err, 1.0e-15_wp)
  end subroutine check_elastic_range

  subroutine check_from_material()
    type(strength_t) :: st
    real(wp) :: err
    integer :: bad
    bad = 0
    if (strength_model_from_name('none') /= strength_none) bad = bad + 1
    if (strength_model_from_name('') /= strength_none) bad = bad + 1
    if (strength_model_from_name('elastic') /= strength_elastic) bad = bad + 1
    if (strength_model_from_name('perfectly_plastic') /= strength_perfectly_plastic) &
      bad = bad + 1
    if (strength_model_from_name('linear_hardening') /= strength_linear_hardening) bad = bad + 1
    if (strength_model_from_name('johnson_cook') /= strength_johnson_cook) bad = bad + 1
    if (strength_model_from_name('viscoplastic_power_law') /= strength_viscoplastic) &
      bad = bad + 1
    if (strength_model_from_name('von_mises') /= -1) bad = bad + 1
    call check_error('strength_model_from_name (wrong answers)', real(bad, wp), 0.0_wp)
    st = strength_from_material(material_t(strength_model='perfectly_plastic', &
      shear_modulus=1.0e9_wp, yield0=1.0e8_wp))
    err = abs(st%t_ref - 298.0_wp) + abs(st%taylor_quinney - 0.9_wp) &
      + abs(st%eps_rate0 - 1.0_wp) + abs(st%h)
    if (st%t_melt < huge(1.0_wp)) err = err + 1.0_wp
    call check_error('strength_from_material defaults (T_ref, Taylor-Quinney, T_melt, ...)', err, &
      0.0_wp)
    bad = 0
    if (len_trim(strength_problem(copper)) > 0) bad = bad + 1
    if (len_trim(strength_problem(hmx)) > 0) bad = bad + 1
    if (len_trim(strength_problem(cu_taylor)) > 0) bad = bad + 1
    st = copper
    st%g = 0.0_wp
    if (len_trim(strength_problem(st)) == 0) bad = bad + 1
    st = hmx
    st%vp_m = 1.2_wp
    if (len_trim(strength_problem(st)) == 0) bad = bad + 1
    st = strength_from_material(material_t(strength_model='tresca'))
    if (len_trim(strength_problem(st)) == 0) bad = bad + 1
    call check_error('strength_problem accepts the library sets, refuses G = 0, m >= 1, tresca', &
      real(bad, wp), 0.0_wp)
  end subroutine check_from_material

  !> n random symmetric trial stresses: a deviator with sigma_eq uniform in
  !> [lo, hi] * ref (returned in dev, with sigma_eq in sig) plus a random trace of about
  !> trace_ratio * ref.
  subroutine random_trials(n, ref, lo, hi, trace_ratio, s, dev, sig)
    integer, intent(in) :: n
    real(wp), intent(in) :: ref, lo, hi, trace_ratio
    real(wp), intent(out) :: s(n, 6), dev(n, 6), sig(n)
    real(wp) :: third, seq(n), p
    integer :: i, a
    do i = 1, n
      do a = 1, 6
        dev(i, a) = 2.0_wp * uniform() - 1.0_wp
      end do
      third = sum(dev(i, 1:3)) / 3.0_wp
      dev(i, 1:3) = dev(i, 1:3) - third
      third = sum(dev(i, 1:3)) / 3.0_wp
      dev(i, 1:3) = dev(i, 1:3) - third
    end do
    call von_mises(n, dev, seq)
    do i = 1, n
      dev(i, :) = dev(i, :) * (ref * (lo + (hi - lo) * uniform()) / seq(i))
    end do
    call von_mises(n, dev, sig)
    do i = 1, n
      p = trace_ratio * ref * (2.0_wp * uniform() - 1.0_wp)
      s(i, :) = dev(i, :)
      s(i, 1:3) = s(i, 1:3) + p
    end do
  end subroutine random_trials

  !> Park-Miller minimal standard generator: reproducible on every compiler.
  real(wp) function uniform()
    seed = mod(16807_i8 * seed, 2147483647_i8)
    uniform = real(seed, wp) / 2147483647.0_wp
  end function uniform

  pure real(wp) function second_invariant(s)
    real(wp), intent(in) :: s(6)
    second_invariant = 0.5_wp * sum(s(1:3)**2) + sum(s(4:6)**2)
  end function second_invariant

  pure function to_matrix(s) result(m)
    real(wp), intent(in) :: s(6)
    real(wp) :: m(3, 3)
    m = reshape([s(1), s(4), s(6), s(4), s(2), s(5), s(6), s(5), s(3)], [3, 3])
  end function to_matrix

  pure function identity() result(m)
    real(wp) :: m(3, 3)
    m = 0.0_wp
    m(1, 1) = 1.0_wp
    m(2, 2) = 1.0_wp
    m(3, 3) = 1.0_wp
  end function identity

end program test_strength
