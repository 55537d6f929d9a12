"""The mission's decisions, pure: where to explore next, where to stand to see or reach an object,
what evidence confirms a candidate.

Each module takes plain inputs (a grid snapshot, a pose, memory objects and anchors, the clock
time, a ``decisions.*`` settings section) and returns plain outputs (a goal cell, a verdict with
its reason); the mission tree's behaviours (``trees/behaviours/``) only poll them and post what
they decide. Nothing here ticks a tree, sends a message or talks to an actor.

- ``config``: every threshold, one typed field each (``hiconav config --describe``)
- ``frontiers``: which frontier of the WTRP order to go to, spent viewpoints, pushes, squeezes,
  the look-around and the idle clock (``Explore``)
- ``viewing``: where to stand to see or verify an object (``VerifyTarget``)
- ``confirmation``: what evidence confirms a candidate, and the verdict with its reason
- ``verification``: one verification's state and next step (judge, move, glance, fallback)
- ``approach``: the final ring, the straight-in step, the creep, when the robot is there
- ``geometry``: approach cells, the 2D line of sight past walls, what an anchor's camera shows
- ``cells``: the view or approach cell near a candidate's footprint, with its fallbacks
- ``progress``: the stall clock (no progress toward a goal)
"""
