"""Physics of the confined friction test as small pure functions (Durand et al. 2016).

* :mod:`.bars`   Hopkinson bar formulae, eq. 2-7 and 14;
* :mod:`.cell`   Janssen-type sample model, eq. 8-13 and 17-21;
* :mod:`.design` stationary-state design relations, eq. 15-16;
* :mod:`.tube`   thick tube and hoop gauge (docs/physics.md section 6).

Units SI, stresses and forces positive in compression.
"""
