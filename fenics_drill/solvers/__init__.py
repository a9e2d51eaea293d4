"""The solver layer: one Newton on the saddle-point system (76) shared by the static equilibrium
(Section 6.4) and the Newmark step (67)-(69), step-size control, the time loop and its energy budget.
Solvers know the model, never files or studies."""
