"""Signal conditioning: the stage between a force *recording* and the model.

A real sensor adds noise and offsets that the package's synthetic scenes do
not have, and it samples at its own rate.  Fed raw, white noise of 10 mN
drives the fast afferents (FA-II fire ~100 pulses/s on a free sensor at
1 kHz) and the result depends on the sample rate.  `Conditioner` applies, in
this order and causally (each output sample depends only on the inputs up to
it, so a stream and an offline run give the same numbers, bit for bit):

1. **Resampling to the model rate** ``fs_out``: a zero-order hold onto the
   output grid (input sample k covers outputs ``ceil(k r) .. ceil((k+1) r) - 1``,
   ``r = fs_out / fs_in``) and a 2nd-order Butterworth low-pass at
   ``min(0.45 fs_in, 0.45 fs_out, bandwidth_hz)`` run at the faster of the two
   rates (an anti-imaging filter upsampling, an anti-aliasing one
   downsampling).  The hold's steps become smooth ramps, where linear
   interpolation would put a kink, an acceleration impulse, at every sample.
2. **Noise gate** (``noise_n`` > 0): each axis is split by a ramp-following
   tracker of bandwidth ``slow_hz`` (`_tracker`) into a slow band, kept
   (held, step 3, then smoothed by a low-pass at 2 ``slow_hz``), and a fast band, soft-thresholded at ``4 noise_n``
   (``sign(x) max(|x| - 4 noise_n, 0)``).  Sensor noise, almost all of it in
   the fast band, is removed, on a hold and during a ramp alike; a ramp's
   corners and a vibration larger than the threshold pass, smaller by the
   threshold.
3. **Force hold** (``shear_hold_n``, ``normal_hold_n`` > 0; `hold_band`): the
   kept band's tangential and normal force move only when they leave a band
   around their last value (a play operator per axis).  The band's width is
   the setting or five SDs of the noise ``noise_n`` leaves in the band held,
   whichever is larger (`hold_widths`; at 100 Hz and 20 mN, 41 mN
   tangential and 52 mN normal: the same per-sample SD puts ten times more
   noise per hertz into the slow band at 100 Hz than at 1 kHz).  A drag
   that lasts is a ramp: the band narrows to the setting within ~20 ms, so
   a ramp passes with its slope, ``shear_hold_n`` behind, at every sample
   rate.  When the drag ends the output *settles* for 1/``slow_hz`` on
   the mean of the unfiltered input since then, so a ramp's lag is made up
   at the ramp's pace and the tracker's overshoot of its end is not kept;
   then it holds, and nothing creeps (a re-centring at 0.5 Hz, here before,
   moved a sheared hold at 0.01-0.07 N/s, which the most sensitive FA-I read
   through the shear term).  The normal hold acts before the slow band's
   smoothing and narrows to half the force above ``contact_on_n``, so
   contact starts when it would without it.
4. **Contact and shear**: contact starts when the gated F_Z rises above
   ``contact_on_n`` and ends when it falls below ``contact_off_n``
   (hysteresis); F_Z becomes ``max(F_Z - contact_on_n, 0)`` (continuous, so a
   contact onset is no force step), and out of contact the shear is zero.  In
   contact the tangential force keeps its direction and loses
   ``shear_deadband_n`` of its magnitude, so noise at zero shear cannot spin
   its direction.

**The noise the sensor shows** (``adapt_noise``): ``noise_n`` is the most the
stage expects.  The noise is measured as the samples stream (`noise_scale`:
second differences, a percentile tracker), and a scale ``min(1, 6 measured /
noise_n)`` multiplies the gate, the holds' widths, the part of
``contact_on_n`` taken off F_Z and the hysteresis, and divides the tracker's
and the smoothing's bandwidths: a sensor of ``noise_n / 6`` or more is
conditioned as declared, a quiet one passes nearly as recorded, with no lag
at contact and release.

``mode="zero_phase"`` (offline only) resamples by monotone cubic
interpolation, runs both filters forwards and backwards and averages the
shear hold run both ways: no lag, but not causal, so a stream cannot
reproduce it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ddmm.population.stimuli._conditioning_kernels import (
    GateSettings,
    GateState,
    StreamSettings,
    StreamState,
    gate_hold_contact,
    hold_band,
    hold_counts,
    noise_scale,
    push_steady,
    smooth_band,
    sos_filter,
    track_band,
)
from ddmm.utils.validation import as_finite_array, check_count, check_instance, check_positive

__all__ = ["Conditioning", "Conditioner", "condition_forces", "noise_allowance", "CONDITIONING_MODES"]

CONDITIONING_MODES = ("causal", "zero_phase")
_ORDER = 2  # the low-passes: 2nd-order Butterworth
_GATE = 4.0  # the fast band's threshold, in multiples of noise_n: 3 left FA-II 3 pulses/s in a hold
_SMOOTH = 2.0  # the slow band's smoothing low-pass, in multiples of slow_hz
# The force hold's width is at least this many SDs of the noise in the band it holds (`hold_widths`): at 4 the
# slow band's excursions still dragged the held shear at 0.4-0.5 N/s in some sheared holds at 100 Hz.
_HOLD_SDS = 5.0
# A drag that lasts is a ramp, not noise: the band narrows to its setting with this time constant, so a ramp
# recorded at 100 Hz lags as one recorded at 1 kHz (at 50 ms SA-I's worst rate ratio was 0.01-0.015 higher).
_NARROW_S = 0.02
# `hold_widths` entries that the normal hold (before the smoothing) and the shear hold (after it) each use.
_NORMAL_ONLY = np.array([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0])
_SHEAR_ONLY = np.array([1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 0.0])
# `track_noise`: the first estimate is the RMS of this many second differences (at least), over this long (s);
# then the percentile tracker's time constant (s) and its fastest step (log); the estimate's margin; the time
# constants (s) of the scale's rise and fall toward the tracker.
_NOISE_FIRST, _NOISE_FIRST_S, _NOISE_TAU_S, _NOISE_STEP, _NOISE_MARGIN = 20, 0.02, 0.1, 0.05, 6.0
_SCALE_RISE_S, _SCALE_FALL_S, _SCALE_SMOOTH_S = 0.05, 0.5, 0.02


@dataclass(frozen=True)
class Conditioning:
    """Settings of the conditioning stage (see the module docstring for the steps).

    Attributes
    ----------
    noise_n : float
        Sensor noise SD in newtons; the fast band is soft-thresholded at four
        times it.  0 turns the gate off.  Default 0.02 N (covers 5-20 mN).
    slow_hz : float
        Bandwidth of the tracker that splits the slow band (kept) from the
        fast band (gated), Hz.  Default 4 Hz (5 Hz let 10 mN of noise at
        100 Hz move FA-I's ramp rates by 20%; docs/recordings.md).
    bandwidth_hz : float or None
        The sensor's bandwidth: a low-pass at this frequency, Hz (None: only
        the resampling filter, at 0.45 of the slower rate).
    contact_on_n, contact_off_n : float
        Contact hysteresis thresholds on the gated F_Z, newtons (on > off).
    shear_deadband_n : float
        Tangential magnitude taken off in contact, newtons.
    shear_hold_n : float
        Least width of the shear hold, newtons: the kept band's tangential
        force moves only when the input leaves +- the width around it (a
        play operator), so noise on a sheared hold cannot wobble the shear;
        the width grows to five SDs of the noise the band carries where that
        is larger, and a ramp trails by this setting.  0 turns it off.
        Default 0.025 N (docs/recordings.md gives the measurement).
    normal_hold_n : float
        Least width of the same hold on the normal force, newtons (0: off).
        Default 0.025 N, the shear hold's: a ramp passes at most this far
        behind (2.5 ms at 10 N/s, 12.5 ms at 2 N/s).
    mode : {"causal", "zero_phase"}
        Causal filters (offline and streaming) or forward-backward ones
        (offline only).
    adapt_noise : bool
        Measure the sensor's noise as it streams and condition for the
        smaller of it (times a margin) and ``noise_n`` (`track_noise`): a
        quiet sensor passes nearly as recorded, with no lag at contact.
        False: always ``noise_n``, as if the sensor were that noisy.
    """

    noise_n: float = 0.02
    slow_hz: float = 4.0
    bandwidth_hz: float | None = None
    contact_on_n: float = 0.03
    contact_off_n: float = 0.015
    shear_deadband_n: float = 0.03
    shear_hold_n: float = 0.025
    normal_hold_n: float = 0.025
    mode: str = "causal"
    adapt_noise: bool = True

    def __post_init__(self):
        for name in ("noise_n", "contact_off_n", "shear_deadband_n", "shear_hold_n", "normal_hold_n"):
            _check_number(getattr(self, name), name, lambda x: x >= 0.0, ">= 0 (N)")
        _check_number(self.slow_hz, "slow_hz", lambda x: x > 0.0, "> 0 (Hz)")
        _check_number(self.contact_on_n, "contact_on_n", lambda x: x > self.contact_off_n,
                      f"> contact_off_n = {self.contact_off_n:g} (N)")
        if self.bandwidth_hz is not None:
            _check_number(self.bandwidth_hz, "bandwidth_hz", lambda x: x > 0.0, "> 0 (Hz) or None")
        if not isinstance(self.adapt_noise, bool):
            raise TypeError(f"adapt_noise must be True or False, got {self.adapt_noise!r}")
        if self.mode not in CONDITIONING_MODES:
            raise ValueError(f"mode={self.mode!r} is not allowed; allowed: {', '.join(CONDITIONING_MODES)}")


def noise_allowance(conditioning: Conditioning) -> float:
    """How far below 0 N a recorded F_Z may read as sensor noise: ``contact_on_n + 5 noise_n`` (N)."""
    return conditioning.contact_on_n + 5.0 * conditioning.noise_n


def _check_number(value, name, ok, allowed):
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not (number and math.isfinite(value) and ok(value)):
        shown = f"{float(value):g}" if number else repr(value)
        raise ValueError(f"{name} must be a finite number {allowed}, got {shown}")


def _lowpass(cutoff_hz: float, fs: float):
    from scipy.signal import butter

    return butter(_ORDER, cutoff_hz, fs=fs, output="sos")


def _tracker(bandwidth_hz: float, fs: float):
    """A critically damped alpha-beta tracker as second-order sections: it follows a ramp with no lag.

    Per sample: predict ``x + v``, correct by the residual ``r`` with gains
    ``g = 1 - q^2`` (position) and ``h = (1 - q)^2`` (velocity per sample),
    ``q = exp(-2 pi bandwidth_hz / fs)``.  A low-pass would lag a 6 N/s ramp
    by ~0.27 N at 5 Hz, and the noise riding on that lag would pass the gate.
    """
    from scipy.signal import ss2tf, tf2sos

    q = math.exp(-2.0 * math.pi * bandwidth_hz / fs)
    g, h = 1.0 - q * q, (1.0 - q) ** 2
    a = np.array([[1.0 - g, 1.0 - g], [-h, 1.0 - h]])
    b = np.array([[g], [h]])
    c = np.array([[1.0, 0.0]])
    num, den = ss2tf(a, b, c @ a, c @ b)
    return tf2sos(num[0], den)


class Conditioner:
    """The causal conditioning of one stream of forces: push chunks in, conditioned samples at ``fs_out`` out.

    Parameters
    ----------
    conditioning : Conditioning
        Settings (``mode`` must be ``"causal"``).
    fs_in, fs_out : float
        Sample rates of the recording and of the model, Hz.
    n_sites : int or None
        Chunks are (n, 3), or (n, n_sites, 3) for a sensor array.

    Attributes
    ----------
    widths : ndarray, shape (7,)
        The force hold's widths in newtons (x, y, z), the contact threshold
        at which the normal hold narrows to nothing, and the widths' floors
        (x, y, z: the settings), from `hold_widths`.

    Examples
    --------
    >>> c = Conditioner(Conditioning(), fs_in=100.0, fs_out=1000.0)
    >>> out, contact = c.push(np.tile([0.0, 0.0, 2.0], (50, 1)))
    >>> out.shape, bool(contact[-1])
    ((500, 3), True)
    >>> [round(float(w), 3) for w in c.widths[:3]]  # widened: 20 mN of noise at 100 Hz
    [0.041, 0.041, 0.052]
    """

    def __init__(self, conditioning: Conditioning, fs_in: float, fs_out: float, n_sites: int | None = None):
        if not isinstance(conditioning, Conditioning):
            raise TypeError(f"conditioning must be a Conditioning, got {type(conditioning).__name__}")
        if conditioning.mode != "causal":
            raise ValueError("a Conditioner (a stream) is causal; mode='zero_phase' exists offline only")
        self.settings, self.n_sites = conditioning, None if n_sites is None else check_count(n_sites, "n_sites")
        self._want = (3,) if self.n_sites is None else (self.n_sites, 3)  # a chunk's shape but its length
        self.fs_in, self.fs_out = check_positive(fs_in, "fs_in", "Hz"), check_positive(fs_out, "fs_out", "Hz")
        cutoff = min(0.45 * self.fs_in, 0.45 * self.fs_out, conditioning.bandwidth_hz or math.inf)
        self._up = self.fs_out >= self.fs_in
        self._sos_rate = _lowpass(cutoff, max(self.fs_in, self.fs_out))
        self._sos_slow = _tracker(min(conditioning.slow_hz, 0.45 * self.fs_out), self.fs_out)
        # The tracker's response falls only as 1/f: smooth what it keeps, or noise at 100-300 Hz
        # (a few % of it) still drives FA-II in a hold.  Lag here delays the signal; it opens no gate.
        self._sos_smooth = _lowpass(min(_SMOOTH * conditioning.slow_hz, 0.45 * self.fs_out), self.fs_out)
        self._k = 0  # input samples consumed
        self._zi_rate = None
        self._slow_state = self._smooth_state = None  # `track_band`'s and `smooth_band`'s, from the first chunk
        self._contact = self._held = self._track = None
        self._noise = None  # `track_noise`'s state, from the first chunk
        self._steady = None  # `push_steady`'s (settings, state), once the states have started
        self._noise_rates = _noise_rates(self.fs_in)
        self._scale_gamma = 1.0 - math.exp(-1.0 / (_SCALE_SMOOTH_S * self.fs_out))
        self._moves = _hold_moves(conditioning, self.fs_out)
        self.widths = hold_widths(conditioning, *self._band_noise())

    def _band_noise(self):
        """SD of what the hold sees per newton of white sensor noise: the tracker's band (the normal hold)
        and that band smoothed (the shear hold), from the filters' responses to one input sample."""
        from scipy.signal import sosfilt

        ratio = self.fs_out / self.fs_in
        if self._up:  # one input sample, held over its output samples and filtered at the output rate; each
            # output sample sums the responses of the inputs 1/ratio apart, hence the division
            pulse = np.zeros(int(2.0 * self.fs_out) + 1)
            pulse[:max(round(ratio), 1)] = 1.0
            rate = sosfilt(self._sos_rate, pulse) / math.sqrt(ratio)
        else:  # decimated after the anti-aliasing filter: about white at fs_out, of this SD
            pulse = np.zeros(int(2.0 * self.fs_in) + 1)
            pulse[0] = 1.0
            gain = math.sqrt(float(np.sum(sosfilt(self._sos_rate, pulse) ** 2)))
            rate = np.zeros(int(2.0 * self.fs_out) + 1)
            rate[0] = gain
        slow = sosfilt(self._sos_slow, rate)
        smooth = sosfilt(self._sos_smooth, slow)
        return math.sqrt(float(np.sum(slow ** 2))), math.sqrt(float(np.sum(smooth ** 2)))

    def _shape(self, forces):
        forces = as_finite_array(forces, "forces")
        if forces.ndim != len(self._want) + 1 or forces.shape[1:] != self._want:
            raise ValueError(f"forces must have shape (n, {', '.join(map(str, self._want))}), got {forces.shape}")
        return forces.reshape(forces.shape[0], -1)

    def _picks(self, n: int) -> np.ndarray:
        """Indices (within the next ``n`` input samples) of the inputs the output grid samples (downsampling)."""
        first = math.ceil(self._k * self.fs_out / self.fs_in - 1e-9)
        last = math.ceil((self._k + n) * self.fs_out / self.fs_in - 1e-9)
        m = np.arange(first, last, dtype=float)
        return np.floor(m * (self.fs_in / self.fs_out) + 1e-9).astype(np.int64) - self._k

    def _filter(self, sos, x, which):
        from scipy.signal import sosfilt_zi

        zi = getattr(self, which)
        if zi is None:  # start in the steady state of the first sample: an offset is not a step
            zi = np.ascontiguousarray(sosfilt_zi(sos)[:, :, None] * x[0][None, None, :])
            setattr(self, which, zi)
        return sos_filter(sos, np.ascontiguousarray(x), zi)

    def _counts(self, n: int) -> np.ndarray:
        """Output samples each of the next ``n`` input samples covers: held (upsampling) or picked (0 or 1)."""
        if self._up:
            return hold_counts(self._k, n, self.fs_out / self.fs_in)
        return np.bincount(self._picks(n), minlength=n).astype(np.int64)

    def _resample(self, x, counts):
        if self._up:
            return self._filter(self._sos_rate, np.repeat(x, counts, axis=0), "_zi_rate")
        return self._filter(self._sos_rate, x, "_zi_rate")[counts.astype(bool)]

    def _noise_scale(self, x, counts):
        """The noise scale (`noise_scale`) of the input samples ``x`` on the output grid (1: the declared noise)."""
        s = self.settings
        if not (s.adapt_noise and s.noise_n > 0):
            return np.ones((int(counts.sum()), x.shape[1]))
        if self._noise is None:
            self._noise = np.zeros((7, x.shape[1]))
            self._noise[2], self._noise[6] = -2.0, np.nan  # two samples before the first difference
        # smoothed at the output rate: a scale held per input sample would step the offset and the hold's band
        # (FA-II fired at 0.1-1 pulses/s in holds at 100 Hz and 5 mN on those steps)
        return noise_scale(np.ascontiguousarray(x), s.noise_n, self._noise_rates, self._noise, counts,
                           self._scale_gamma)

    def push(self, forces):
        """Condition the next chunk of recorded samples.

        Returns
        -------
        forces : ndarray, shape (m, 3) or (m, n_sites, 3)
            Conditioned forces at ``fs_out`` (``m`` depends on where the chunk
            falls on the output grid), F_Z >= 0.
        contact : ndarray of bool, shape (m,) or (m, n_sites)
            The contact state per output sample.
        """
        steady = self._steady or self._start_steady()
        if steady and type(forces) is np.ndarray and forces.shape[1:] == self._want and forces.shape[0] \
                and forces.dtype == np.float64 and forces.flags.c_contiguous:  # a live push: one kernel call
            finite, y, contact = push_steady(forces, self._k, self.widths, *steady)
            if finite:  # else `_shape` raises
                self._k += forces.shape[0]
                return self._out(y, contact)
        x = self._shape(forces)
        sites = x.shape[1] // 3
        if x.shape[0] == 0:
            return self._out(np.empty((0, x.shape[1])), np.empty((0, sites), bool))
        counts = self._counts(x.shape[0])
        scale = self._noise_scale(x, counts).reshape(-1, sites, 3)
        y = self._resample(x, counts)
        self._k += x.shape[0]
        if y.shape[0] == 0:
            return self._out(y, np.empty((0, sites), bool))
        widths = self.widths
        if self.settings.noise_n > 0:
            slow, kept = self._bands(y, scale.reshape(y.shape), widths * _NORMAL_ONLY)
            gate, widths = _GATE * self.settings.noise_n, widths * _SHEAR_ONLY
        else:
            slow, kept, gate = y, y, -1.0
        return self._out(*self._finish(y, slow, kept, gate, widths, scale))

    def _start_steady(self):
        """`push_steady`'s settings and state (the general path's, shared), once that path has started them."""
        if not self._up or self._held is None:
            return None
        s, unused = self.settings, np.zeros((7, self._held.size))  # `unused`: states the settings never read
        gate = (_GATE * s.noise_n if s.noise_n > 0 else -1.0, self.widths, self._moves, s.contact_on_n,
                s.contact_off_n, s.shear_deadband_n)  # a GateSettings's fields
        settings = StreamSettings(self._sos_rate, self.fs_out / self.fs_in, s.noise_n, s.adapt_noise and s.noise_n > 0,
                                  self._noise_rates, self._scale_gamma, (s.slow_hz, _SMOOTH * s.slow_hz, 0.45 *
                                  self.fs_out, self.fs_out), np.stack([_NORMAL_ONLY, _SHEAR_ONLY]), gate)
        state = StreamState(self._zi_rate, unused if self._noise is None else self._noise,
                            unused[:2] if self._slow_state is None else self._slow_state,
                            unused[:2] if self._smooth_state is None else self._smooth_state,
                            (self._held, self._track, self._contact, self._taken))  # a GateState's fields
        self._steady = tuple(settings), tuple(state)  # plain tuples: numba types them ~3x faster than named ones
        return self._steady

    def _bands(self, y, scale, normal):
        """The tracker's slow band and the kept band (the normal hold, then the smoothing), both as wide as
        the measured noise allows (`track_band`, `smooth_band`: the declared noise's bandwidths at scale 1)."""
        cap, c = 0.45 * self.fs_out, self.settings
        if self._slow_state is None:
            self._slow_state, self._smooth_state = np.full((2, y.shape[1]), np.nan), np.full((2, y.shape[1]), np.nan)
        slow = track_band(y, scale, c.slow_hz, cap, self.fs_out, self._slow_state)
        # The normal hold acts before the smoothing, which rounds its corners: a corner of the held F_Z is
        # a step of its velocity, and unsmoothed it drove FA-II in holds (0.3 pulses/s at 100 Hz, 20 mN).
        # The shear hold stays after it (FA-I's shear term fired more in sheared holds the other way).
        held = self._hold(slow, y, normal, scale.reshape(-1, y.shape[1] // 3, 3))
        return slow, smooth_band(held, scale, _SMOOTH * c.slow_hz, cap, self.fs_out, self._smooth_state)

    def _hold(self, slow, y, widths, scale):
        """The force hold (`hold_band`) on a copy of the tracker's slow band, its state carried over."""
        if widths[:3].max() <= 0.0:
            return slow
        sites = slow.shape[1] // 3
        self._start_hold(slow[0], sites)
        held = slow.reshape(slow.shape[0], sites, 3).copy()
        hold_band(held, y.reshape(held.shape), widths, self._moves, self._held, self._track, scale)
        return held.reshape(slow.shape)

    def _finish(self, y, slow, kept, gate, widths, scale):
        """Gate, force hold of ``widths`` N per axis, contact and deadband (`gate_hold_contact`), state carried
        over; ``scale`` (n, sites, 3) is the noise scale per output sample."""
        s, sites = self.settings, y.shape[1] // 3
        if self._contact is None:
            self._contact, self._taken = np.zeros(sites, bool), np.zeros(sites)
        self._start_hold(kept[0], sites)
        shape = (y.shape[0], sites, 3)
        settings = GateSettings(gate, widths, self._moves, s.contact_on_n, s.contact_off_n, s.shear_deadband_n)
        carry = GateState(self._held, self._track, self._contact, self._taken)
        return gate_hold_contact(y.reshape(shape), slow.reshape(shape), kept.reshape(shape),
                                 np.ascontiguousarray(scale), settings, carry)

    def _start_hold(self, first, sites):
        """The hold's state, from the first sample it sees (a copy: the hold updates it in place)."""
        if self._held is None:
            self._held = np.array(first.reshape(sites, 3))
            self._track = _start_track(sites)

    def _out(self, y, contact):
        if self.n_sites is None:
            return y.reshape(-1, 3), contact.reshape(-1)
        return y.reshape(-1, self.n_sites, 3), contact.reshape(-1, self.n_sites)


def condition_forces(forces, fs_in: float, fs_out: float, conditioning: Conditioning | None = None):
    """Condition a whole recording (offline): conditioned forces at ``fs_out`` and the contact state.

    ``mode="causal"`` gives exactly what a `Conditioner` (a stream) gives for
    the same samples, whatever the chunking; ``mode="zero_phase"`` resamples
    by monotone cubic interpolation and filters forwards and backwards.

    Parameters
    ----------
    forces : array_like, shape (n, 3) or (n, n_sites, 3)
        Recorded forces in newtons, uniformly sampled at ``fs_in``.
    fs_in, fs_out : float
        Sample rates of the recording and of the output, Hz.
    conditioning : Conditioning, optional
        Settings (default `Conditioning()`).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> noisy = np.column_stack([rng.normal(0, 0.01, (1000, 2)), 2.0 + rng.normal(0, 0.01, 1000)])
    >>> out, contact = condition_forces(noisy, 1000.0, 1000.0)
    >>> bool(np.all(out[200:, :2] == 0.0)), bool(contact[200:].all())
    (True, True)
    """
    conditioning = Conditioning() if conditioning is None else conditioning
    check_instance(conditioning, "conditioning", Conditioning, "a Conditioning or None")
    forces = as_finite_array(forces, "forces")
    n_sites = None if forces.ndim == 2 else forces.shape[1]
    if conditioning.mode == "causal":
        return Conditioner(conditioning, fs_in, fs_out, n_sites).push(forces)
    from ddmm.population.stimuli._zero_phase import zero_phase

    return zero_phase(forces, fs_in, fs_out, conditioning, n_sites)


def hold_widths(conditioning: Conditioning, tracker_sd: float = 0.0, smooth_sd: float = 0.0) -> np.ndarray:
    """`hold_band`'s widths: the force hold's per axis (x, y, z), the contact threshold at which the normal
    hold narrows to nothing, and the floors (x, y, z) to which a lasting drag narrows it, all in newtons.

    An axis's width is its setting or `_HOLD_SDS` times the SD that the sensor noise (``noise_n``) leaves
    in the band the hold sees, whichever is larger: ``smooth_sd`` (shear) and ``tracker_sd`` (normal) are
    those SDs per newton of white noise at the recording's rate.  At 100 Hz the slow band carries ten
    times more noise per hertz than at 1 kHz for the same per-sample SD, and a fixed width let its rare
    excursions drag the held force at up to 0.7 N/s.
    """
    noise = _HOLD_SDS * conditioning.noise_n
    shear = max(conditioning.shear_hold_n, noise * smooth_sd) if conditioning.shear_hold_n > 0 else 0.0
    normal = max(conditioning.normal_hold_n, noise * tracker_sd) if conditioning.normal_hold_n > 0 else 0.0
    floors = [conditioning.shear_hold_n, conditioning.shear_hold_n, conditioning.normal_hold_n]  # the settings
    return np.array([shear, shear, normal, conditioning.contact_on_n, *floors])


def _noise_rates(fs: float) -> np.ndarray:
    """`track_noise`'s rates at an input rate ``fs`` Hz: the differences of its first estimate, the tracker's
    step up (log; down a third of it) and the estimate's margin."""
    first = max(_NOISE_FIRST, round(_NOISE_FIRST_S * fs))
    return np.array([float(first), min(_NOISE_STEP, 3.0 / (_NOISE_TAU_S * fs)), _NOISE_MARGIN,
                     min(1.0, 1.0 / (_SCALE_RISE_S * fs)), min(1.0, 1.0 / (_SCALE_FALL_S * fs))])


def _hold_moves(conditioning: Conditioning, fs: float) -> np.ndarray:
    """`hold_band`'s rates at ``fs`` Hz: the settling's approach per sample (a fraction: the slow band's
    smoothing frequency, so a ramp's end is rounded as that smoothing rounds it), the settling's length in
    samples (one period of the tracker's bandwidth, by which its overshoot of a ramp's end has decayed) and
    the band's narrowing per dragged sample (a fraction: time constant `_NARROW_S`)."""
    return np.array([1.0 - math.exp(-2.0 * math.pi * _SMOOTH * conditioning.slow_hz / fs),
                     fs / conditioning.slow_hz, 1.0 - math.exp(-1.0 / (_NARROW_S * fs))])


def _start_track(sites: int) -> np.ndarray:
    """`hold_band`'s initial ``track`` (sites, 3, 4): settling, at the approach's own pace, so the hold starts
    on the mean of its first 1/slow_hz seconds of input rather than on the first (noisy) sample."""
    track = np.zeros((sites, 3, 4))
    track[:, :, 0] = np.inf
    return track
