"""The Brian2 device the engine builds with: C++ standalone with three costs removed.

Imported only when a project is generated (it imports Brian2).  Measured on a
3,168-neuron x 10,000-step block (CHANGELOG.md, the Brian2 engine entry of 0.1.0):

* **Thresholder** (`templates/threshold.cpp`): Brian2's
  template tests and records each neuron in one branchy loop, the largest
  cost of the run (user time 32 -> 20 ms a block).  Ours tests 64 neurons at
  a time in a loop that vectorises and records only where a block crossed.
  The condition, the indices recorded and their order are Brian2's.
* **Network loop** (`generate_network_source`): Brian2's loop reads the
  process CPU clock after every time step, a system call (about 0.45 us,
  4.5 ms a block) that only feeds the run's reported duration.  The
  duration is read once after the loop instead.
* **Current table** (`input_function`): read through a memory map of the
  run's file instead of a `TimedArray` copied into fresh memory on every
  run (system time 8 -> 3.6 ms a block).

Every other template is Brian2's own, through a derived `Templater`.
"""

from __future__ import annotations

from types import SimpleNamespace

from brian2.devices.cpp_standalone.codeobject import CPPStandaloneCodeObject
from brian2.devices.cpp_standalone.device import CPPStandaloneDevice

__all__ = ["EngineCodeObject", "EngineDevice", "TABLE_ENV", "drop_per_step_clock", "input_function",
           "sort_clock_settings"]

_PER_STEP = """        current = std::clock();
        elapsed_realtime = (double)(current - start)/(1 * CLOCKS_PER_SEC);
"""
_AFTER_LOOP = "    Network::_globally_running = false;\n"
_ONCE = "    elapsed_realtime = (double)(std::clock() - start)/(1 * CLOCKS_PER_SEC);\n"


class EngineCodeObject(CPPStandaloneCodeObject):
    """Brian2's standalone code object with the engine's templates looked up first."""

    templater = CPPStandaloneCodeObject.templater.derive("ddmm.models.engines.brian2", templates_dir="templates")


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


def sort_clock_settings(queue: list, start: int = 0) -> None:
    """Put each run of consecutive clock start-value settings in ``queue[start:]`` in array-name order, in place.

    `CPPStandaloneDevice.network_run` sets each clock's ``timestep`` and ``t``
    while iterating over a set of clocks, whose order follows their memory
    addresses: two processes generated ``main.cpp`` with the lines swapped, so
    ``make`` relinked a cached binary that was already right.  The settings
    are independent assignments, so their order does not change the program.

    Examples
    --------
    >>> q = [("x", ()), ("set_by_single_value", ("_array_b_clock_t", 0, "0.0")),
    ...      ("set_by_single_value", ("_array_a_clock_t", 0, "0.0")), ("y", ())]
    >>> sort_clock_settings(q)
    >>> [entry[1][0] for entry in q[1:3]]
    ['_array_a_clock_t', '_array_b_clock_t']
    """
    def is_clock(entry) -> bool:
        return entry[0] == "set_by_single_value" and str(entry[1][0]).endswith(("clock_timestep", "clock_t"))

    i = start
    while i < len(queue):
        j = i
        while j < len(queue) and is_clock(queue[j]):
            j += 1
        if j - i > 1:
            queue[i:j] = sorted(queue[i:j], key=lambda entry: str(entry[1][0]))
        i = max(j, i + 1)


class EngineDevice(CPPStandaloneDevice):
    """`CPPStandaloneDevice` generating with `EngineCodeObject` and a clock-free network loop."""

    def code_object_class(self, codeobj_class=None, fallback_pref=None):
        return EngineCodeObject if codeobj_class is None else codeobj_class

    def network_run(self, net, *args, **kwargs):
        """Brian2's, with the clocks' start values set in name order (Brian2 sets them in a set's order)."""
        start = len(self.main_queue)
        super().network_run(net, *args, **kwargs)
        sort_clock_settings(self.main_queue, start)

    def generate_network_source(self, writer, compiler):
        limit = self._maximum_run_time
        network = self.code_object_class().templater.network(
            None, None, maximum_run_time=None if limit is None else float(limit))
        if limit is None:
            network = SimpleNamespace(cpp_file=drop_per_step_clock(network.cpp_file), h_file=network.h_file)
        writer.write("network.*", network)


#: Environment variable naming the current table file of a run (the lane's ``ddmm_current.dat``).
TABLE_ENV = "DDMM_CURRENT_TABLE"

_INPUT_CPP = r"""
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
// The current table, (@N_SAMPLES@, @N_NEURONS@) float64 in row-major order,
// memory-mapped when the binary starts from the file named by $@TABLE_ENV@:
// the page cache's pages themselves, with no copy and no allocation.
static const double* ddmm_map_table()
{
    const size_t size = (size_t)@N_SAMPLES@ * (size_t)@N_NEURONS@ * sizeof(double);
    const char* path = std::getenv("@TABLE_ENV@");
    const int fd = path ? open(path, O_RDONLY) : -1;
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || (size_t)st.st_size != size)
    {
        std::fprintf(stderr, "Error reading the current table '%s': expected a file of %zu bytes\n",
                     path ? path : "($@TABLE_ENV@ unset)", size);
        std::exit(1);
    }
    void* table = mmap(NULL, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    close(fd);
    if (table == MAP_FAILED)
    {
        std::fprintf(stderr, "Error mapping the current table '%s'\n", path);
        std::exit(1);
    }
    return (const double*)table;
}
static const double* const ddmm_table = ddmm_map_table();
// Neuron i's current at time t, held from sample to sample: t is a sample
// time k/fs of the operation's clock, so the rounding gives k exactly.
static inline double ddmm_input(const double t, const int i)
{
    long sample = (long)(t * @FS@ + 0.5);
    sample = sample < 0 ? 0 : (sample >= @N_SAMPLES@ ? @N_SAMPLES@ - 1 : sample);
    return ddmm_table[sample * @N_NEURONS@ + i];
}
"""


def input_function(n_samples: int, n_neurons: int, fs: float):
    """The Brian2 function ``ddmm_input(t, i)``: the current of neuron ``i`` at time ``t``, from the mapped table.

    Brian2's `TimedArray` would read its values from a run-argument file
    into memory it allocates (a 25 MB copy, plus zeroing the pages, on
    every run); this maps the lane's file instead (3.5-4.5 ms less per
    3,168-neuron x 1,000-sample block).  The table is ``(n_samples,
    n_neurons)`` float64; ``fs`` is its sample rate in Hz.
    """
    from brian2 import check_units, implementation, second

    code = _INPUT_CPP
    for token, value in (("N_SAMPLES", str(int(n_samples))), ("N_NEURONS", str(int(n_neurons))),
                         ("TABLE_ENV", TABLE_ENV), ("FS", repr(float(fs)))):
        code = code.replace(f"@{token}@", value)

    @implementation("cpp", code)
    @check_units(t=second, i=1, result=1)
    def ddmm_input(t, i):
        raise NotImplementedError("ddmm_input exists only in the compiled Brian2 engine")

    return ddmm_input
