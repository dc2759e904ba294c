"""The paper's gate frame, one wing of gatetherm: everything that knows this one machine.

It makes a plain :class:`~gatetherm.studies.run.case.Case` (:func:`gatetherm.frame.case.gate_frame`)
that every command, study and API function runs like a case file's, and owns what only this frame has:

- :mod:`~gatetherm.frame.geometry`: its parameters (:class:`FrameParams`, :class:`MeshParams`), boxes,
  sensor points and checks; :mod:`~gatetherm.frame.build`: its gmsh builder and mesh-size estimate;
- :mod:`~gatetherm.frame.problem`: its problem (:class:`ModelConfig`, :func:`frame_problem`), effect
  targets and the mesh check; :mod:`~gatetherm.frame.config`: its model file (``--config``);
- :mod:`~gatetherm.frame.beam`: the beam theory; :mod:`~gatetherm.frame.loadcases`: FE load cases at the tips;
- :mod:`~gatetherm.frame.conditions`: the paper's conditions 1-3 as oil-supply schedules (and the sensor
  study's held-out default);
- :mod:`~gatetherm.frame.case`: the case generator, its origin (which offers the compensator its beam
  coefficients) and the paper's conditions run on it; :mod:`~gatetherm.frame.sweeppoint` and
  :mod:`~gatetherm.frame.design`: its side of a parametric study (``sweeppoint.FRAME``) and its design study.

Layer: after ``gatetherm.studies``, before ``gatetherm.validation``. The root package, geometry,
solvers and studies never import it (``tests/test_architecture.py``); validation, the API and the
CLI do.
"""
