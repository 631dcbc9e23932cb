"""Cohort and parameter studies (scripts/study.py): the study file and its cases (spec), a case's
directory and run (cases), the local pool and the Slurm array (local_runner, slurm_runner), the
aggregated table and plots (table)."""
