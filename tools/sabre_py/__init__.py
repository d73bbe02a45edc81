"""Python side of SABRE: readers for the solver's HDF5/CSV output, exact solutions
(Riemann, Sedov) and the pieces shared by the command-line tools in tools/ and the
regression runner regress/run.  Runs with Debian's /usr/bin/python3 (numpy, h5py,
matplotlib, vtk)."""


def run_main(main):
    """sys.exit(main()) for a command-line tool, quietly when its output is piped into head
    and the like (BrokenPipeError)."""
    import os
    import sys
    try:
        sys.exit(main())
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(1)
