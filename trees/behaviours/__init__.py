"""Built-in node types of mission trees: py_trees composites/decorators and the mission behaviours.

Importing this package registers them in ``hiconav.trees.registry.BEHAVIOURS``.
"""

from hiconav.decisions.geometry import approach_cell
from hiconav.trees.behaviours import approach, composites, explore, mission, verify  # noqa: F401  (registration)
from hiconav.trees.behaviours.approach import Approach
from hiconav.trees.behaviours.base import MissionBehaviour
from hiconav.trees.behaviours.explore import Explore
from hiconav.trees.behaviours.mission import HealthOk, ParseInstruction, ReturnToStart, Stop, TargetConfirmed
from hiconav.trees.behaviours.verify import VerifyTarget

__all__ = ["Approach", "Explore", "HealthOk", "MissionBehaviour", "ParseInstruction", "ReturnToStart", "Stop",
           "TargetConfirmed", "VerifyTarget", "approach_cell"]
