!> Unit test of the decomposition kinetics (m_reaction; manual/reaction.md section 4):
!> Henson's one-step rates against the published values at 1000 and 1500 K; the constant-
!> volume adiabatic explosion from 1000 K stepped as the solver steps it (burn at frozen T,
!> then T += Q / cv d lambda) against a quadrature of t(lambda) = int dl / ((1 - l) k(T(l)))
!> and against scipy's solution of the same ODE (1.91982e-7 s to lambda = 1/2, computed with
!> solve_ivp, rtol 1e-11); the Frank-Kamenetskii estimate cv T0^2 / (Q T_a k(T0)) for scale;
!> one row of the solver's kernel (heat = rho Q d lambda); Tarver's three steps against a
!> fine Runge-Kutta integration, their mass and their net heat (5.86 MJ/kg).
program test_reaction
  use m_kinds, only: wp
  use m_comm, only: comm_init
  use m_reaction, only: reaction_t, reaction_from_name, arrhenius_rate, burn_step, &
    reaction_row, tarver3_t, tarver3_hmx, tarver3_step, henson_a, henson_t_act
  use m_test_check, only: check_start, check, check_close, check_done
  implicit none
  type(reaction_t) :: rt
  type(tarver3_t) :: tc
  real(wp), parameter :: cv = 1500.0_wp, q = 5.5e6_wp, t0 = 1000.0_wp
  real(wp) :: t_step, t_quad, t_fk, y(4), yr(4), heat, h
  real(wp) :: temp(3), rho(3), rl(3), re(3)
  integer :: i, n
  call comm_init()
  call check_start('reaction_unit')
  rt = reaction_from_name('henson', q)
  call check_close('henson T_a (K)', rt%t_act, 17922.0_wp, 2.0_wp)
  call check_close('henson k(1000 K) (1/s)', arrhenius_rate(rt%a, rt%t_act, 1000.0_wp), &
    9.2e4_wp, 0.0_wp, 0.01_wp)
  call check_close('henson k(1500 K) (1/s)', arrhenius_rate(rt%a, rt%t_act, 1500.0_wp), &
    3.6e7_wp, 0.0_wp, 0.01_wp)
  rt = reaction_from_name('', q)
  call check('no reaction is none', rt%model == 0)
  rt = reaction_from_name('henson', q)
  ! the exact step: two half steps equal one step at the same T
  call check_close('burn: two half steps = one step', &
    burn_step(rt, 1200.0_wp, 0.5e-6_wp, burn_step(rt, 1200.0_wp, 0.5e-6_wp, 0.1_wp)), &
    burn_step(rt, 1200.0_wp, 1.0e-6_wp, 0.1_wp), 1.0e-15_wp)

  ! the adiabatic explosion at constant volume
  t_step = explosion_time_stepped()
  t_quad = explosion_time_quadrature(200000)
  t_fk = cv * t0**2 / (q * henson_t_act * arrhenius_rate(henson_a, henson_t_act, t0))
  call check_close('explosion time, quadrature vs scipy (s)', t_quad, 1.91982e-7_wp, 0.0_wp, &
    1.0e-5_wp)
  call check_close('explosion time, stepped vs quadrature (s)', t_step, t_quad, 0.0_wp, &
    2.0e-3_wp)
  call check_close('explosion time vs Frank-Kamenetskii (s)', t_quad, t_fk, 0.0_wp, 0.25_wp)
  print '(a,es12.5,a,es12.5,a,es12.5)', '  explosion from 1000 K to lambda 1/2: stepped ', &
    t_step, ' s, quadrature ', t_quad, ' s, Frank-Kamenetskii ', t_fk

  ! the solver's row kernel: masked cells untouched, heat rho Q d lambda
  temp = [1500.0_wp, 1500.0_wp, 298.0_wp]
  rho = [1900.0_wp, 1900.0_wp, 1900.0_wp]
  rl = 0.0_wp
  re = 1.0e6_wp
  call reaction_row(rt, 3, 1.0e-8_wp, temp, rho, rl, re, [.true., .false., .true.])
  call check_close('row: lambda at 1500 K after 10 ns', rl(1) / rho(1), &
    1.0_wp - exp(-arrhenius_rate(rt%a, rt%t_act, 1500.0_wp) * 1.0e-8_wp), 1.0e-15_wp)
  call check_close('row: heat = rho Q d lambda', re(1) - 1.0e6_wp, rl(1) * q, 1.0e-6_wp)
  call check('row: masked cell untouched', abs(rl(2)) + abs(re(2) - 1.0e6_wp) < tiny(1.0_wp))
  call check('row: 298 K does not burn (d lambda < 1e-20)', rl(3) / rho(3) < 1.0e-20_wp)

  ! Tarver's three steps at 800 K over 1 ms: one exponential step against RK4
  tc = tarver3_hmx()
  y = [1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
  call tarver3_step(tc, 800.0_wp, 1.0e-3_wp, y, heat)
  n = 200000
  h = 1.0e-3_wp / n
  yr = [1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
  do i = 1, n
    yr = rk4(yr, h)
  end do
  do i = 1, 4
    call check_close('tarver3 at 800 K, 1 ms: fraction vs RK4', y(i), yr(i), 1.0e-9_wp)
  end do
  call check_close('tarver3: mass', sum(y), 1.0_wp, 1.0e-13_wp)
  call check_close('tarver3: heat = sum Q x', heat, tc%q(1) * (1.0_wp - y(1)) + tc%q(2) &
    * (1.0_wp - y(1) - y(2)) + tc%q(3) * y(4), 1.0e-6_wp)
  y = [1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
  call tarver3_step(tc, 1500.0_wp, 1.0_wp, y, heat)
  call check_close('tarver3: all burnt at 1500 K after 1 s, net heat (J/kg)', heat, &
    5.8576e6_wp, 1.0_wp)
  call check_done()

contains

  !> Time to lambda = 1/2 from t0, stepped as the solver does: the exact burn at frozen T,
  !> then the heat into T; steps of 1e-4 of the current Frank-Kamenetskii time.
  real(wp) function explosion_time_stepped() result(t)
    real(wp) :: lam, lnew, temp0, dt
    lam = 0.0_wp
    temp0 = t0
    t = 0.0_wp
    do while (lam < 0.5_wp)
      dt = 1.0e-4_wp * cv * temp0**2 / (q * rt%t_act * arrhenius_rate(rt%a, rt%t_act, temp0))
      lnew = burn_step(rt, temp0, dt, lam)
      if (lnew >= 0.5_wp) then
        ! the last part of the step, to land on 1/2 (the rate at frozen T)
        t = t + dt * log((1.0_wp - lam) / 0.5_wp) / log((1.0_wp - lam) / (1.0_wp - lnew))
        return
      end if
      temp0 = temp0 + q / cv * (lnew - lam)
      lam = lnew
      t = t + dt
    end do
  end function explosion_time_stepped

  !> t(1/2) = int_0^1/2 dl / ((1 - l) k(t0 + Q l / cv)), composite Simpson in m intervals.
  real(wp) function explosion_time_quadrature(m) result(t)
    integer, intent(in) :: m
    integer :: j
    real(wp) :: dl, l, w
    dl = 0.5_wp / m
    t = 0.0_wp
    do j = 0, m
      l = j * dl
      w = merge(1.0_wp, merge(4.0_wp, 2.0_wp, mod(j, 2) == 1), j == 0 .or. j == m)
      t = t + w / ((1.0_wp - l) * arrhenius_rate(rt%a, rt%t_act, t0 + q / cv * l))
    end do
    t = t * dl / 3.0_wp
  end function explosion_time_quadrature

  !> One classical RK4 step of Tarver's chain at 800 K.
  function rk4(y0, dt) result(y1)
    real(wp), intent(in) :: y0(4), dt
    real(wp) :: y1(4), k1(4), k2(4), k3(4), k4(4)
    k1 = f(y0)
    k2 = f(y0 + 0.5_wp * dt * k1)
    k3 = f(y0 + 0.5_wp * dt * k2)
    k4 = f(y0 + dt * k3)
    y1 = y0 + dt / 6.0_wp * (k1 + 2.0_wp * k2 + 2.0_wp * k3 + k4)
  end function rk4

  function f(yy) result(dy)
    real(wp), intent(in) :: yy(4)
    real(wp) :: dy(4), k(3)
    k = arrhenius_rate(tc%z, tc%t_act, 800.0_wp)
    dy = [-k(1) * yy(1), k(1) * yy(1) - k(2) * yy(2), k(2) * yy(2) - k(3) * yy(3), &
      k(3) * yy(3)]
  end function f

end program test_reaction
