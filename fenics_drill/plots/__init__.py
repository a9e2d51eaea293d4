"""The plots layer: figures drawn from saved files only (runs, Monte Carlo studies, operating windows);
units are converted here and nowhere else."""
