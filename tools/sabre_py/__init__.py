"""Python side of SABRE: readers for the solver's HDF5/CSV output, exact solutions
(Riemann, Sedov) and the pieces shared by the command-line tools in tools/ and the
regression runner regress/run.  Runs with Debian's /usr/bin/python3 (numpy, h5py,
matplotlib, vtk)."""
