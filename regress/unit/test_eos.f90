!> Unit test of m_eos: round trips e(rho, p) -> p(rho, e), the sound speed against a finite
!> difference of the isentrope (c^2 = dp/drho|_e + p / rho^2 dp/de|_rho), and the
!> Mie-Gruneisen pressure on its Hugoniot equal to rho0 Us up.
program test_eos
  use m_kinds, only: wp
  use m_eos, only: eos_t, eos_ideal_gas, eos_stiffened_gas, eos_mie_gruneisen, eos_polynomial, &
    eos_pressure, eos_energy, eos_sound_speed2
  use m_comm, only: comm_init, comm_exit
  implicit none
  type(eos_t) :: air, water, copper, hmx_poly
  integer :: nfail
  call comm_init()
  nfail = 0
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
  if (nfail == 0) then
    write(6, '(a)') 'PASS test_eos'
    call comm_exit(0)
  end if
  write(6, '(a,i0,a)') 'FAIL test_eos: ', nfail, ' checks failed'
  call comm_exit(1)

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
      call report(name // ' round trip p(rho, e(rho, p)) = p', err, 1.0e-12_wp)
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
      call report(name // ' sound speed against finite difference', err, 1.0e-6_wp)
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
      call report('copper Hugoniot pressure = rho0 Us up', err, 1.0e-12_wp)
    end do
  end subroutine check_hugoniot

  subroutine report(what, err, tol)
    character(len=*), intent(in) :: what
    real(wp), intent(in) :: err, tol
    if (err <= tol) return
    nfail = nfail + 1
    write(6, '(a,es10.3,a,es10.3)') '  ' // what // ': error ', err, ' > ', tol
  end subroutine report

end program test_eos
