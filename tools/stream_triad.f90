!> STREAM triad a = b + s c (McCalpin) on arrays far larger than the caches, best of 10
!> repetitions, on every OpenMP thread and on one. Prints the bandwidth in GB/s counting
!> 24 bytes per element (two loads, one store; write-allocate traffic not counted, as STREAM).
program stream_triad
  use, intrinsic :: iso_fortran_env, only: real64, int64
  use omp_lib, only: omp_get_max_threads, omp_get_wtime, omp_set_num_threads
  implicit none
  integer, parameter :: n = 40000000
  real(real64), allocatable :: a(:), b(:), c(:)
  real(real64) :: best_all, best_one
  integer :: nthreads
  allocate(a(n), b(n), c(n))
  nthreads = omp_get_max_threads()
  best_all = triad_best()
  call omp_set_num_threads(1)
  best_one = triad_best()
  write(6, '(a,f8.2,a,i0,a)') 'stream_triad_GBs ', 24.0_real64 * n / best_all / 1.0e9_real64, &
    '  (', nthreads, ' threads)'
  write(6, '(a,f8.2)') 'stream_triad_GBs_one_core ', 24.0_real64 * n / best_one / 1.0e9_real64

contains

  real(real64) function triad_best() result(best)
    integer :: rep, i
    real(real64) :: t, s
    s = 3.0_real64
    !$omp parallel do
    do i = 1, n
      a(i) = 0.0_real64
      b(i) = 1.0_real64
      c(i) = 2.0_real64
    end do
    best = huge(1.0_real64)
    do rep = 1, 10
      t = omp_get_wtime()
      !$omp parallel do
      do i = 1, n
        a(i) = b(i) + s * c(i)
      end do
      best = min(best, omp_get_wtime() - t)
    end do
    if (a(n) < 0.0_real64) write(6, *) a(1)
  end function triad_best

end program stream_triad
