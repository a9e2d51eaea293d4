"""The I/O layer: the files of runs and studies - time series (HDF5/netCDF), fields (XDMF), Monte Carlo
realisations, study directories and JSON - each with its one writer and its one reader."""
