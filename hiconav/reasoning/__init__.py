"""The slow layer: instruction decomposition, subgraph verification (VLM or offline), reasoner.

Paper section "Deep Reasoning". Pure and synchronous except ``vlm_client`` (the project's one
socket user); the pykka ReasoningActor runs ``Reasoner`` + a verifier in its worker thread.
Importing this package is cheap (no model, no network).
"""

from hiconav.reasoning.config import OfflineVerifierConfig, ReasoningConfig, VLMConfig
from hiconav.reasoning.decompose import (
    DEFAULT_VOCABULARY,
    InstructionError,
    OfflineParser,
    decompose_instruction,
    parse_offline,
)
from hiconav.reasoning.hypothesis import TargetHypothesis
from hiconav.reasoning.reasoner import Reasoner, ReasonerStats
from hiconav.reasoning.replies import ReplyError
from hiconav.reasoning.verifier import (
    VERIFIERS,
    OfflineVerifier,
    Verifier,
    VerifyResult,
    VLMVerifier,
    make_verifier,
)
from hiconav.reasoning.vlm_client import ChatResult, VLMClient, image_data_url

__all__ = [
    "DEFAULT_VOCABULARY", "VERIFIERS", "ChatResult", "InstructionError", "OfflineParser", "OfflineVerifier",
    "OfflineVerifierConfig", "Reasoner", "ReasonerStats", "ReasoningConfig", "ReplyError",
    "TargetHypothesis", "VLMClient", "VLMConfig", "VLMVerifier", "Verifier", "VerifyResult",
    "decompose_instruction", "image_data_url", "make_verifier", "parse_offline",
]
