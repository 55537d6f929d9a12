"""Mission trees: py_trees behaviours, the YAML -> tree builder and the mission YAML files.

``build_tree("objectnav")`` loads ``trees/objectnav.yaml``; ``load_tree(path)`` validates a file
and raises ``TreeError`` naming file:line [key]. This package never starts actors.
"""

from hiconav.trees.builder import (
           BlackboardRef,
           NodeDef,
           TreeDefinition,
           build_tree,
           find_tree_file,
           load_tree,
)
from hiconav.trees.context import Candidate, MissionContext
from hiconav.trees.errors import BlackboardError, TreeError
from hiconav.trees.registry import BEHAVIOURS, Param, register_behaviour

__all__ = ["BEHAVIOURS", "BlackboardError", "BlackboardRef", "Candidate", "MissionContext", "NodeDef", "Param",
           "TreeDefinition", "TreeError", "build_tree", "find_tree_file", "load_tree", "register_behaviour"]
