!> run.log (manual/user-guide.md, "Output"): its header (the run, the build, the grid and
!> ranks, the numerics chosen, the phases, which effects are on and why, the state vector and
!> the memory estimate) and its last lines (the fallback and ghost-fluid counts, the
!> conservation fix, wall time by part, cost, balance and memory), which run.json repeats
!> for tools (m_run_report makes both from the same facts). Rank 0 writes (m_errors).
module m_run_log
  use, intrinsic :: iso_fortran_env, only: compiler_version, compiler_options
  use m_kinds, only: wp, i8, line_len
  use m_comm, only: comm_size, comm_min, comm_max, comm_sum, comm_backend_name
  use m_errors, only: log_line
  use m_simulation, only: sim_t
  use m_memory, only: mem_parts, mem_text
  use m_levelset_bodies, only: ls_material
  use m_gfm_cut_close, only: body_shrink
  use m_run_report, only: run_facts_t, run_facts, run_json_write, thermal_reason, halo_line, &
    interfaces_reason
  implicit none
  private
  public :: write_run_header, write_run_footer

contains

  !> run.log's header.
  subroutine write_run_header(s)
    type(sim_t), intent(in) :: s
    character(len=line_len) :: line
    integer :: nb, k, l
    call log_line('SABRE run: ' // trim(s%cfg%title))
    call log_line('deck: ' // trim(s%cfg%deck_file) // '  (resolved copy: ' // &
      trim(s%cfg%out_dir) // '/deck.nml)')
    call log_line('compiler: ' // compiler_version())
    call log_line('build flags: ' // compiler_options())
    nb = size(s%blocks)
    write(line, '(a,i0,a,3(i0,1x),a,3(i0,1x),a,i0,a)') 'grid: ', s%lay%ndim, 'D, cells ', &
      s%lay%cells, ', blocks of ', s%lay%bsize, '(', count(s%lay%active), ' active)'
    call log_line(line)
    if (any(s%lay%nlast /= s%lay%bsize)) then
      write(line, '(a,3(i0,1x),a)') 'grid: the last block along each direction has ', &
        s%lay%nlast, 'cells'
      call log_line(line)
    end if
    write(line, '(a,i0,a,i0,a,i0)') 'ranks: ', comm_size(), ' (' // comm_backend_name // &
      ' build); blocks per rank: min ', comm_min(nb), ', max ', comm_max(nb)
    call log_line(line)
    write(line, '(a,a,a,a,a,a,a,i0,a,f5.3)') 'numerics: scheme ', trim(s%cfg%scheme), &
      ' (', trim(s%cfg%variables), ' variables), flux ', trim(s%cfg%flux), ', rk_order ', &
      s%cfg%rk_order, ', cfl ', s%cfg%cfl
    call log_line(line)
    call log_line('numerics: ' // trim(s%cfg%numerics_note))
    if (s%cfg%overlap) call overlap_line(s)
    if (s%ph%has_strength) call log_line('numerics: flux of eps_p and w_c ' // &
      trim(s%cfg%scalar_flux))
    if (s%ph%has_strength .and. s%ls%n > 0) call log_line('numerics: S, eps_p, w_c across ' // &
      'surface faces: ' // trim(s%cfg%surface_flux))
    do k = 1, s%ph%nphase
      write(line, '(a,i0,a)') 'phase ', k, ': material ' // trim(s%ph%material(k)) // ' (eos ' // &
        trim(eos_name(s, k)) // ')'
      if (k == 1 .and. s%ls%base_flows) line = trim(line) // ', the base'
      do l = 1, s%ls%n
        if (s%ls%phase(l) == k) line = trim(line) // ', body ' // trim(s%ls%name(l))
      end do
      call log_line(line)
    end do
    call log_line('effects: strength ' // trim(s%ph%strength_reason))
    call log_line('effects: thermal ' // thermal_reason(s))
    call log_line('effects: heat conduction ' // trim(s%ph%conduction_reason))
    call log_line('effects: reaction ' // trim(s%ph%reaction_reason))
    call log_line('effects: interfaces ' // trim(interfaces_reason(s)))
    call write_scenes(s)
    if (s%ls%n > 0) call log_line('gfm: cut-cell update ' // trim(s%cut(1)%reason))
    if (s%cut(1)%on .and. any(s%ls%kind == ls_material)) then
      if (s%cut(1)%body_dead > 0.0_wp) then
        write(line, '(a,f5.3,a,f3.1,a)') 'gfm: a body''s level set follows its content where ' &
          // 'they drift apart by more than ', s%cut(1)%body_dead, ' of a cell (grows; shrinks ' &
          // 'beyond ', body_shrink, ' times that: &numerics body_follow)'
      else
        line = 'gfm: a body''s level set does not follow its content (&numerics body_follow = 0)'
      end if
      call log_line(line)
    end if
    if (s%ls%n > 0 .and. s%ph%has_strength) call log_line('gfm: conservation fix ' // &
      trim(s%fix%reason))
    if (s%ph%has_strength) then
      write(line, '(a,i0,a)') 'state: ', s%ph%nvar, ' variables per cell (rho, rho u, rho v, ' // &
        'rho w, rho E, rho S (6), rho eps_p, rho w_c'
    else
      write(line, '(a,i0,a)') 'state: ', s%ph%nvar, ' variables per cell (rho, rho u, rho v, ' // &
        'rho w, rho E'
    end if
    if (s%ph%has_reaction) line = trim(line) // ', rho lambda'
    if (s%ph%nphase > 1) write(line, '(a,a,i0,a)') trim(line), ' per phase x ', s%ph%nphase, &
      ' phases'
    if (s%ls%n > 0) write(line, '(a,a,i0,a)') trim(line), '; ', s%ls%n, ' level sets'
    line = trim(line) // ')'
    call log_line(line)
    call write_memory_estimate(s)
  end subroutine write_run_header

  !> run.log's line on &run overlap (collective): the blocks that are computed while the
  !> halo messages travel, over all ranks (m_step); none on a deck with level sets.
  subroutine overlap_line(s)
    type(sim_t), intent(in) :: s
    character(len=line_len) :: line
    integer(i8) :: nb, nl
    nb = comm_sum(int(size(s%blocks), i8))
    nl = comm_sum(int(count(.not. s%plan%remote), i8))
    if (.not. s%overlap) then
      write(line, '(a, i0, a)') 'overlap: 0 of ', nb, ' blocks (a deck with level sets: the ' &
        // 'ghost-fluid stage needs every halo before any block is computed)'
    else
      write(line, '(a, i0, a, i0, a)') 'overlap: ', nl, ' of ', nb, &
        ' blocks computed while the halo messages travel'
    end if
    call log_line(line)
  end subroutine overlap_line

  !> What the scene generators made of each generated body (manual/scenes.md): how many
  !> spheres, the volume fraction of its box made against the one asked for.
  subroutine write_scenes(s)
    type(sim_t), intent(in) :: s
    character(len=line_len) :: line
    integer :: b
    do b = 1, s%cfg%n_bodies
      associate (body => s%cfg%bodies(b), m => s%made(b))
        select case (trim(body%shape))
        case ('random_spheres')
          write(line, '(a,i0,a,f6.4,a,i0,a)') "scene: body '" // trim(body%name) &
            // "': ", size(m%spheres, 2), ' random spheres, ', m%fraction, &
            ' of the box lo..hi (seed ', body%seed, '; asked: '
          if (body%count > 0) then
            write(line, '(a,a,i0,a)') trim(line), ' count ', body%count, ')'
          else
            write(line, '(a,a,f6.4,a)') trim(line), ' volume_fraction ', body%volume_fraction, ')'
          end if
        case ('random_field')
          write(line, '(a,i0,a,i0,a,i0,a,f6.4,a,i0,a,f6.4,a)') "scene: body '" &
            // trim(body%name) // "': random field on ", size(m%field, 1), ' x ', &
            size(m%field, 2), ' x ', size(m%field, 3), ' points, ', &
            m%fraction, ' of the box lo..hi below its level (seed ', body%seed, &
            '; asked: volume_fraction ', body%volume_fraction, ')'
        case ('grains')
          write(line, '(a,i0,a,es10.3,a,i0,a,f6.4,a,i0,a,f6.4,a)') "scene: body '" &
            // trim(body%name) // "': ", body%count, ' Voronoi grains, binder ', &
            m%grains%thickness, ' m thick, in ', m%grains%ncolour, &
            ' colours (level sets), ', m%fraction, &
            ' of the box lo..hi (seed ', body%seed, '; asked: volume_fraction ', &
            body%volume_fraction, ')'
          if (m%grains%needed > m%grains%ncolour) write(line, '(a,i0,a)') trim(line) &
            // '; colours cut from ', m%grains%needed, ' by &body colours: grains nearer' &
            // ' than the ghost band share level sets'
        case default
          cycle
        end select
        call log_line(line)
      end associate
    end do
  end subroutine write_scenes

  !> The memory estimate made before the grid was allocated (m_simulation), part by part.
  subroutine write_memory_estimate(s)
    type(sim_t), intent(in) :: s
    character(len=line_len) :: line
    integer :: k
    line = 'memory: estimate ' // mem_text(sum(s%mem%parts)) // ' per rank above the ' // &
      'baseline of ' // mem_text(s%mem%base) // ' (part by part:'
    do k = 1, size(mem_parts)
      if (k > 1) line = trim(line) // ','
      line = trim(line) // ' ' // trim(mem_parts(k)) // ' ' // mem_text(s%mem%parts(k))
    end do
    write(line, '(a,a,i0,a)') trim(line), '); this node: ', s%mem%node_ranks, &
      trim(merge(' rank  ', ' ranks ', s%mem%node_ranks == 1)) // ', ' // &
      mem_text(s%mem%node_available) // ' available'
    call log_line(line)
  end subroutine write_memory_estimate

  function eos_name(s, p) result(name)
    type(sim_t), intent(in) :: s
    integer, intent(in) :: p
    character(len=32) :: name
    integer :: k
    name = ''
    do k = 1, s%cfg%n_materials
      if (s%cfg%materials(k)%name == s%ph%material(p)) name = s%cfg%materials(k)%eos
    end do
  end function eos_name

  !> run.log's last lines and run.json, from the same facts (m_run_report).
  subroutine write_run_footer(s, elapsed, loop, base)
    type(sim_t), intent(inout) :: s
    real(wp), intent(in) :: elapsed, loop, base
    character(len=line_len) :: line
    type(run_facts_t) :: f
    f = run_facts(s, elapsed, loop, base)
    write(line, '(a,i0,a,es14.7,a,i0,a,i0,a)') 'end: step ', f%step, ', time ', f%time, &
      ', first-order fallback faces ', f%fallback_faces, ' in all, ', f%first_order_steps, &
      ' steps recomputed at first order'
    call log_line(line)
    write(line, '(a,i0,a)') 'end: ', f%cells_low, ' cells recomputed with ' // &
      'first-order faces by the cell-local fallback'
    call log_line(line)
    if (s%ls%n > 0) then
      write(line, '(a,i0,a,i0,a,i0,a,i0,a,i0,a,i0,a,i0,a)') 'gfm: ', &
        f%gfm(1), ' ghost fills: ', f%gfm(2), &
        ' trilinear (', f%gfm(3), ' with an incomplete stencil), ', &
        f%gfm(4), ' least squares, ', f%gfm(5), &
        ' mean of neighbours, ', f%gfm(6), ' without a real neighbour, ', &
        f%gfm(7), ' ghost pressures limited'
      call log_line(line)
      write(line, '(a,i0,a,i0,a)') 'gfm: ', f%gfm(8), &
        ' ghosts across a material-material interface (MMI), ', &
        f%gfm(9), ' contact ghosts in tension treated as free surfaces'
      call log_line(line)
      write(line, '(a,i0,a,i0,a)') 'gfm: ', f%gfm(10), ' inadmissible cells ' // &
        'within 2 cells of a body surface taken out of the body as debris; ', f%gfm(11), &
        ' right-hand sides of a phase on a block it is absent from not computed'
      call log_line(line)
      if (s%cut(1)%on) then
        write(line, '(a,i0,a,i0,a)') 'gfm: ', comm_sum(int(sum(s%cut%debts(1)), i8)), &
          ' cell-stages of a cut cell in debt (its fluxes drew out more mass than it held) ' &
          // 'repaid by its small-cell group, ', comm_sum(int(sum(s%cut%debts(2)), i8)), &
          ' that no group could repay'
        call log_line(line)
        write(line, '(a,i0,a)') 'gfm: ', comm_sum(int(sum(s%cut%lonely), i8)), &
          ' cell-stages of a small cell that no group held (a sheet or spray thinner than ' &
          // 'a cell) mixed with its ring (theory.md 7b)'
        call log_line(line)
        write(line, '(a,i0,a)') 'gfm: ', comm_sum(int(sum(s%cut%soundless), i8)), &
          ' cell-stages of a small cell whose content had a real sound speed at no density ' &
          // '(kinetic energy beyond its total) showed its step-start state; its content ' &
          // 'at the step''s end stranded (history.csv cut_stranded_*, theory.md 7b)'
        call log_line(line)
      end if
      if (size(s%cut) > 1) then
        write(line, '(a,i0,a)') 'gfm: ', comm_sum(int(sum(s%cut%contacts), i8)), &
          ' cell-stages of a contact between cut phases exchanged traction and work ' // &
          '(m_gfm_cut_contact)'
        call log_line(line)
      end if
      if (s%fix%on) then
        write(line, '(a,es11.4,a,f8.4,a,es11.4,a)') 'gfm: conservation fix took out ', &
          f%fixed(1), ' kg (', f%fixed_percent(1), ' % of the solids'' mass) and ', &
          f%fixed(2), ' J ('
        if (s%fix%energy) then
          write(line, '(a,f8.4,a)') trim(line), f%fixed_percent(2), ' % of their energy); '
        else
          line = trim(line) // 'energy part off); '
        end if
        write(line, '(a,1x,i0,a)') trim(line), f%fix_clamped, &
          ' fixes held to a tenth of the surface content'
        call log_line(line)
        write(line, '(a,i0,a)') 'gfm: conservation fix left aside in ', f%fix_aside, &
          ' steps when a solid crossed an open (outflow) side of the domain'
        call log_line(line)
      end if
      write(line, '(a,f9.3,a,f9.3,a)') 'gfm: ghost fill ', f%gfm_s, ' s, reinitialisation ', &
        f%reinit_s, ' s'
      call log_line(line)
    end if
    write(line, '(a,f10.3,a,f9.3,a,f9.3,a,f9.3,a,f9.3,a)') 'wall time ', f%wall, &
      ' s: fluxes ', f%fluxes, ' s, halo+bc ', f%halo, ' s, dt ', f%dt, ' s, output ', &
      f%output, ' s'
    call log_line(line)
    write(line, '(a,es11.4,a,es11.4,a)') 'cost: ', real(f%cell_steps, wp), ' cell-steps, ', &
      real(f%cell_steps, wp) / max(f%wall, 1.0e-9_wp) / comm_size(), &
      ' cell-steps per second per rank'
    call log_line(line)
    write(line, '(a,es11.4,a,f10.3,a)') 'loop: ', real(f%cell_steps, wp), ' cell-steps in ', &
      f%loop, ' s'
    call log_line(line)
    call log_line(halo_line(f))
    write(line, '(a,f10.3,a,f10.3,a)') 'balance: work per rank (fluxes, ghost fill, ' // &
      'reinitialisation, dt) min ', f%work_min, ' s, max ', f%work_max, ' s'
    call log_line(line)
    if (s%bal%nchecks > 0) then
      associate (n => s%bal%nchecks, nm => s%bal%nmoves)
        write(line, '(a,i0,a,f7.3,a,f7.3,a,f7.3,a,i0,a,i0,a,f8.3,a)') 'balance: ', n, &
          ' checks, imbalance max ', maxval(s%bal%checks(2, 1:n)), ', mean ', &
          sum(s%bal%checks(2, 1:n)) / n, ', last ', s%bal%checks(2, n), '; ', nm, &
          ' migrations (', nint(sum(s%bal%moves(2, 1:nm))), ' blocks, ', &
          sum(s%bal%moves(5, 1:nm)), ' s)'
      end associate
      call log_line(line)
      write(line, '(a,f10.3,a,f10.3,a)') 'balance: stage work over the checks, largest ' // &
        'rank ', sum(s%bal%checks(3, 1:s%bal%nchecks)), ' s, mean ', &
        sum(s%bal%checks(4, 1:s%bal%nchecks)), ' s (processor time)'
      call log_line(line)
    end if
    write(line, '(a,f10.1,a,f10.1,a,f8.1,a)') 'memory: peak resident ', f%peak / 1024**2, &
      ' MB over all ranks (', f%base / 1024**2, ' MB before the grid), ', f%per_cell, &
      ' bytes per cell above the baseline'
    call log_line(line)
    write(line, '(a,f8.1,a)') 'memory: solver arrays ', f%arrays_per_cell, ' bytes per ' // &
      'cell (state with halo, start-of-step copy, right-hand side)'
    call log_line(line)
    call run_json_write(s, f, trim(s%cfg%out_dir) // '/run.json')
    call log_line('results: ' // trim(s%cfg%out_dir))
  end subroutine write_run_footer

end module m_run_log
