"""The paper's finite-element model: 2-D Quad4 plates and frictional interfaces, inertial dynamics, event-driven drive.

Modules, one concept each: :mod:`.random` (pcg32), :mod:`.yield_strains`, :mod:`.quad4` (element),
:mod:`.materials`, :mod:`.assembly` (linear operators), :mod:`.model` (the model as arrays),
:mod:`.laws` (the interface laws), :mod:`.backends` (how the numbers are computed; a prepared backend
owns the state, :mod:`.backends.base`; the numba CPU kernels in :mod:`.backends.cpu`), :mod:`.stack`
(the state with its held yield strains), :mod:`.relaxation` and :mod:`.equilibrium` (how a kicked stack
comes to rest), :mod:`.linear_response`, :mod:`.loading` and :mod:`.event_driven` (the quasistatic
steps along the linear response), :mod:`.protocol` and :mod:`.thermal` (the sequence of loads,
perturbations and relaxations), :mod:`.simulation` (their composition), :mod:`.observables`,
:mod:`.run` (the increment loop with resume, writing the ``fem-run`` format of
:mod:`stickslip.formats.fem_run`), :mod:`.replay`, :mod:`.errors`. The specification is
shared/reference-model.md; docs/fem.md documents equations, units and the file layout.
"""
