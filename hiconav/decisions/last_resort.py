"""The last resort of an explored-out search: the best candidate set aside only as out of reach.

A search ends in failure when no frontier is left and no candidate is due. Some of the
candidates set aside by then were never judged wrong: verification found no view point it could
reach, or the approach no free cell within its rings (a coffee machine behind a kitchen island,
a toilet in a bathroom whose door the inflated map closes, a chair pushed under a table). Ending
with nothing fails for certain; stopping as near the best of them as the map allows may succeed,
and costs nothing that was not already lost. So once, when the search is explored out, the
mission takes that candidate back (``pick``), skips the verification it could not make, and
the approach settles for the reachable cell nearest it on rings out to ``last_resort_m``
(``approach.rings(wide=True)``), or stops where it stands, facing it.

Pure: memory objects and the mission's reasons of rejection in; a node out. The ``Explore``,
``VerifyTarget`` and ``Approach`` behaviours poll this (and ``approach.rings``,
``approach.without_cell``) and post.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from typing import Any

#: the source of a last-resort candidate (``Candidate.source``)
SOURCE = "last-resort"


def pick(objects: Iterable[Any], out_of_reach: Mapping[int, str], confirmed: Collection[int]) -> Any | None:
    """The memory node to stop by, or None: among ``objects`` (memory nodes with ``id``,
    ``confidence``, ``n_obs``) those set aside only as out of reach (``out_of_reach``: object id
    -> the reason), those the reasoning layer ``confirmed`` (hypotheses) first, then the most
    evidence (confidence x observations), then the lower id."""
    stranded = [o for o in objects if int(o.id) in out_of_reach]
    if not stranded:
        return None
    return min(stranded, key=lambda o: (int(o.id) not in confirmed, -float(o.confidence) * int(o.n_obs), int(o.id)))


__all__ = ["SOURCE", "pick"]
