"""Sane upper bounds shared by the settings models, robot profiles and behaviour parameters.

A rate or a timeout far beyond these is a typo or hostile input (``.inf`` Hz, a timeout of
years), not a choice: the models refuse it at load with the field's name. Constants only: this
module must stay importable from every config module (no imports).
"""

from __future__ import annotations

#: highest rate (Hz) of any loop, actor or stream
MAX_RATE_HZ = 1000.0
#: longest timeout, latency, deadline or time limit (s): one day
MAX_DURATION_S = 86400.0
