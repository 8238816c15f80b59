"""The paper's finite-element model: 2-D Quad4 plates and cusp interfaces, inertial dynamics, event-driven drive.

Modules, one concept each: :mod:`.random` (pcg32), :mod:`.yield_strains`,
:mod:`.quad4` (element), :mod:`.materials`, :mod:`.assembly` (linear operators),
:mod:`.model` (arrays of model and state), :mod:`.forces`, :mod:`.dynamics`
(velocity Verlet), :mod:`.minimise`, :mod:`.event_driven`, :mod:`.system`
(protocol steps), :mod:`.observables`, :mod:`.run` (the increment loop with resume, writing
the ``fem-run`` format of :mod:`stickslip.formats.fem_run`). The specification is shared/reference-model.md;
docs/fem.md documents equations, units and the file layout.
"""
