"""The Brian2 device the engine builds with: C++ standalone with two per-step costs removed.

Imported only when a project is generated (it imports Brian2).  Measured on a
3,168-neuron x 10,000-step block (docs/performance.md, issue 11):

* **Thresholder** (`models/brian2_templates/threshold.cpp`): Brian2's
  template tests and records each neuron in one branchy loop, the largest
  cost of the run (user time 32 -> 20 ms a block).  Ours tests 64 neurons at
  a time in a loop that vectorises and records only where a block crossed.
  The condition, the indices recorded and their order are Brian2's.
* **Network loop** (`generate_network_source`): Brian2's loop reads the
  process CPU clock after every time step, a system call (about 0.45 us,
  4.5 ms a block) that only feeds the run's reported duration.  The
  duration is read once after the loop instead.

Every other template is Brian2's own, through a derived `Templater`.
"""

from __future__ import annotations

from types import SimpleNamespace

from brian2.devices.cpp_standalone.codeobject import CPPStandaloneCodeObject
from brian2.devices.cpp_standalone.device import CPPStandaloneDevice

__all__ = ["EngineCodeObject", "EngineDevice", "drop_per_step_clock"]

_PER_STEP = """        current = std::clock();
        elapsed_realtime = (double)(current - start)/(1 * CLOCKS_PER_SEC);
"""
_AFTER_LOOP = "    Network::_globally_running = false;\n"
_ONCE = "    elapsed_realtime = (double)(std::clock() - start)/(1 * CLOCKS_PER_SEC);\n"


class EngineCodeObject(CPPStandaloneCodeObject):
    """Brian2's standalone code object with the engine's templates looked up first."""

    templater = CPPStandaloneCodeObject.templater.derive("models", templates_dir="brian2_templates")


def drop_per_step_clock(source: str) -> str:
    """``network.cpp`` reading the CPU clock once after the loop instead of after every step.

    Returns ``source`` unchanged unless Brian2's per-step read appears
    exactly once (another Brian2 version, OpenMP or a maximum run time).

    >>> drop_per_step_clock("no loop here")
    'no loop here'
    """
    if source.count(_PER_STEP) != 1 or source.count(_AFTER_LOOP) != 1:
        return source
    return source.replace(_PER_STEP, "").replace(_AFTER_LOOP, _AFTER_LOOP + _ONCE)


class EngineDevice(CPPStandaloneDevice):
    """`CPPStandaloneDevice` generating with `EngineCodeObject` and a clock-free network loop."""

    def code_object_class(self, codeobj_class=None, fallback_pref=None):
        return EngineCodeObject if codeobj_class is None else codeobj_class

    def generate_network_source(self, writer, compiler):
        limit = self._maximum_run_time
        network = self.code_object_class().templater.network(
            None, None, maximum_run_time=None if limit is None else float(limit))
        if limit is None:
            network = SimpleNamespace(cpp_file=drop_per_step_clock(network.cpp_file), h_file=network.h_file)
        writer.write("network.*", network)
