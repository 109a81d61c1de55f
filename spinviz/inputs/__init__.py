"""One schema for every input: scene files, render options, atlas specs and the arguments of
the Python API -- typed, frozen request objects validated by pydantic v2, shared by TOML,
the command line and Python so that an input is checked in one place.

Where each input is declared (one request class per table or call; its fields are the TOML
keys or the keyword arguments):

============================  ===============================================================
``inputs.scene``              ``[body]``, ``[initial]``, ``[simulation]``, ``[observe]``, the top
``inputs.render``             ``RenderSpec`` (``[render]``, and ``render``'s keywords);
                              ``RenderArguments`` (``t``, ``t_end``, ``workers``, ``out`` ...)
``inputs.simulation``         ``SimulationRequest``: ``spinviz.simulate``'s arguments, which a
                              scene also becomes (``Scene.request(model)``)
``inputs.trajectory``         ``Trajectory.sample``'s times, ``Trajectory.radiation``'s line of sight
``inputs.atlas``              the atlas spec's tables; ``AtlasArguments`` (``spinviz.atlas``)
``inputs.options``            the study commands' counts and horizons (``check --sweep``,
                              ``bench``, ``atlas --evidence``) and the cap on their work
``inputs.base``               the field types and the translation of errors
``inputs.toml``               reading a TOML file; a table checked with file and key in errors
============================  ===============================================================

How validation goes.  A request class is a frozen pydantic dataclass in strict mode (a string
is never read as a number, nor a float as an integer, nor a bool as either; NaN and infinities
are refused).  Each field carries its type and range (``Annotated[Real, between(lo, hi,
why)]``); rules joining fields are a ``model_validator`` raising ``SpecError(key, reason)``.
Construction raises ``SpecError`` (a ValueError) or ``SpecTypeError`` (also a TypeError)
naming the field -- never pydantic's ``ValidationError``.  The name is the caller's own:

* a TOML table is read by ``toml.table``: ``SceneError(path, "[simulation].samples", ...)``;
* a Python call sees the argument: ``SpecError("step", "must be positive, got 0")``;
* the command line maps the argument to its option: ``--workers: must be at most 2, ...``.

Limits that depend on more than a value -- the spin scale, the number of turns a horizon
means, memory, an atlas's run time -- are checked by the request that knows them
(``SimulationRequest``, ``regimes.engine.cost.check_feasible``), before any work.

To add a key: one annotated field in the request class of its table (type, range with the
reason, default, a line in the class docstring).  The TOML key, the keyword argument, the
error messages and -- for an atlas spec -- the spec's identity follow from it
(``inputs.atlas`` says how ``[run]`` keys reach ``inputs.atlas_spec.Settings``).  A command-line
option for it is one ``add_argument`` in its command's module (``spinviz.commands.<name>``)
whose ``dest`` is the argument's name: the dispatcher names a schema error by that option,
and ``tests/test_options_fuzz.py`` fuzzes it from the parser.

Importing this package loads nothing; its modules load pydantic when a scene, a spec or a
call is first validated (~65 ms once per process with the schema's classes, measured on this
machine; render workers pay it too, since the frame plan carries its ``RenderSpec``).
"""
