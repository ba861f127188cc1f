"""Shared test settings: hypothesis profiles and a loopback-only Lab Streaming Layer configuration.

The Brian2 build cache is the user's own (``DDMM_CACHE_DIR`` or ``~/.cache/ddmm``), as a user's runs would
share it; tests that damage or race builds use a cache of their own.
"""

import os
import tempfile

from hypothesis import HealthCheck, settings

settings.register_profile(
    "default", max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile("ci", max_examples=40, deadline=None, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci" if os.environ.get("CI") else "default")

ENGINES = ("direct", "brian2")

# Lab Streaming Layer: loopback only, whatever the host's config.  liblsl reads the file named by
# LSLAPICFG on first use, so it is set here, before any test imports pylsl (and inherited by the
# `ddmm` subprocesses the tests start).
_LSL_CONFIG = os.path.join(tempfile.mkdtemp(prefix="ddmm-lsl-"), "lsl_api.cfg")
with open(_LSL_CONFIG, "w", encoding="utf-8") as _f:
    _f.write("[ports]\nIPv6 = disable\n[multicast]\nResolveScope = machine\n[lab]\nKnownPeers = {127.0.0.1}\n"
             "[log]\nlevel = -3\n")
os.environ["LSLAPICFG"] = _LSL_CONFIG
