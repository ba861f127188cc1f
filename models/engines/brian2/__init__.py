"""The Brian2 engine: eqs 4-6 in Brian2's C++ standalone mode, with its device, lanes and templates.

- `engine`: builds one standalone project per shape, caches it, and runs
  the binary on each block (`run_brian2`);
- `device`: `EngineDevice`, Brian2's standalone device with three costs
  removed, and the ``ddmm_input`` function that maps the current table;
- `lanes`: private input/result folders so concurrent runs do not collide;
- ``templates/``: the one template of ours (``threshold.cpp``); every other
  template is Brian2's own.

Brian2 internals this engine relies on
--------------------------------------
The engine is pinned to Brian2 2.9 (``brian2==2.9.*`` in ``pyproject.toml``;
the build key includes ``brian2.__version__``).  It relies on these parts of
Brian2 that are not public API; each has a test that fails if a Brian2
release changes it:

1. **Subclassing** ``brian2.devices.cpp_standalone.device.CPPStandaloneDevice``
   (`device.EngineDevice`), overriding ``code_object_class`` and
   ``generate_network_source``, and reading its private
   ``_maximum_run_time``.  Guarded by
   ``tests/models/test_engines.py::test_brian2_network_loop_reads_the_clock_once``
   and every engines-identical test.
2. **The network template's text**: the per-step ``std::clock()`` lines and
   the ``Network::_globally_running = false;`` line of ``network.cpp``, which
   `device.drop_per_step_clock` moves after the loop (left unchanged when
   they do not appear exactly once).  Guarded by
   ``test_brian2_network_loop_reads_the_clock_once``.
3. **A modified copy of Brian2's ``threshold.cpp`` template**
   (``templates/threshold.cpp``), found first through
   ``CPPStandaloneCodeObject.templater.derive``.  Same condition, indices and
   order as Brian2's.  Guarded by
   ``test_engines_identical_across_thresholder_blocks`` and
   ``test_engines_identical_on_random_currents``.
4. **The standalone binary's command line**: ``./main --results_dir DIR``
   and run arguments ``afferents.NAME=FILE`` / ``afferents.t_end=VALUE``,
   run directly with ``LD_BIND_NOW=1`` as ``device.run`` does, and result
   files located with ``device.get_array_filename``.  Guarded by
   ``test_continuing_from_state_equals_one_run`` and the identical tests.
5. **Brian2 reports a run argument's file of the wrong size only on
   stderr and exits 0**: the engine treats "Error" on stderr as a failure.
   Guarded by ``test_brian2_refuses_an_input_file_it_could_not_read``.
6. **Object names reused after ``device.reinit()`` and a garbage
   collection**, so a cached project's names match and nothing recompiles.
   Guarded by ``test_brian2_compiles_once_per_shape``.
7. **Logging and preferences**: ``BrianLogger``'s handlers and the prefs
   ``logging.display_brian_error_message``, ``logging.save_script``,
   ``codegen.cpp.extra_compile_args_gcc`` and
   ``devices.cpp_standalone.openmp_threads``.  Guarded by
   ``tests/models/test_hard_cases.py::test_brian2_does_not_take_over_python_warnings``
   and ``test_brian2_log_warnings_become_python_warnings``.

Public Brian2 API used as documented: ``NeuronGroup``, ``run_regularly``,
``SpikeMonitor``, ``Network``, ``set_device``, ``implementation`` and
``check_units`` (for the C++ function ``ddmm_input``).

Importing this package does not import Brian2; `engine` does, when a
project is first built.
"""

__all__ = ["run_brian2", "cache_dir", "import_brian2"]


def __getattr__(name):
    if name in __all__:
        from . import engine

        return getattr(engine, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
