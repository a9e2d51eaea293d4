"""Compiled numerics the model runs on: Numba helpers that an interrupt still stops, FFCx's element kernels
called from Numba, rows of the basis packed by field, and the banded saddle-point solve of the full order.

Imports nothing from the rest of :mod:`fenics_drill.model`: the physics and the reduction build on it."""
