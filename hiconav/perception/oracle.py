"""The oracle detector: detections read from the simulator's ground-truth instance channel.

It stands in for a real open-vocabulary detector in evaluation runs, so it is noisy on purpose
(misses, spurious boxes, label confusion between similar categories, a minimum pixel area) and
deterministic per (seed, frame.seq). Every detection it makes carries ``source="oracle"`` and it
logs that the oracle is in use, so that results obtained with it are never reported as if a real
detector had produced them. It must only be used with frames that carry ``Frame.instances``.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np
from scipy import ndimage

from hiconav.errors import FrameError
from hiconav.perception.config import OracleConfig
from hiconav.perception.detector import DETECTORS, normalise_label
from hiconav.types import Detection, Frame

__all__ = ["DEFAULT_CONFUSIONS", "CounterDraws", "OracleDetector"]

log = logging.getLogger(__name__)

# Similar categories a real detector mixes up (symmetric closure is taken below).
DEFAULT_CONFUSIONS: dict[str, tuple[str, ...]] = {
    "sofa": ("armchair", "bed"),
    "armchair": ("sofa", "chair"),
    "chair": ("armchair", "stool"),
    "stool": ("chair",),
    "tv": ("laptop", "monitor"),
    "laptop": ("tv",),
    "bed": ("sofa",),
    "dining_table": ("coffee_table", "desk"),
    "coffee_table": ("dining_table", "side_table"),
    "desk": ("dining_table",),
    "plant": ("vase",),
    "toilet": ("sink",),
    "sink": ("toilet", "bathtub"),
    "fridge": ("cabinet",),
    "dresser": ("cabinet", "shelving_unit"),
}


def _closure(table: dict[str, Sequence[str]]) -> dict[str, tuple[str, ...]]:
    out: dict[str, set[str]] = {}
    for a, bs in table.items():
        a = normalise_label(a)
        for b in bs:
            b = normalise_label(b)
            if a != b:
                out.setdefault(a, set()).add(b)
                out.setdefault(b, set()).add(a)
    return {k: tuple(sorted(v)) for k, v in out.items()}


_MASK64 = (1 << 64) - 1


def _splitmix64(x: int) -> int:
    """One SplitMix64 output for the 64-bit input ``x`` (Steele et al. 2014)."""
    x = (x + 0x9E3779B97F4A7C15) & _MASK64
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & _MASK64
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & _MASK64
    return x ^ (x >> 31)


class CounterDraws:
    """Uniform draws that depend only on (seed, seq, key): a SplitMix64 stream started from a
    hash of the three. The detector needs a handful of draws per object per frame; seeding a
    numpy Generator for each cost ~50 us, a third of the oracle's time per frame."""

    __slots__ = ("_state",)

    def __init__(self, seed: int, seq: int, key: int) -> None:
        self._state = _splitmix64(_splitmix64(_splitmix64(seed & _MASK64) ^ (seq & _MASK64)) ^ (key & _MASK64))

    def _next(self) -> int:
        self._state = (self._state + 1) & _MASK64
        return _splitmix64(self._state)

    def random(self, n: int | None = None) -> float | list[float]:
        """One uniform in [0, 1) (53 bits), or a list of ``n``."""
        if n is None:
            return (self._next() >> 11) * (1.0 / (1 << 53))
        return [(self._next() >> 11) * (1.0 / (1 << 53)) for _ in range(n)]

    def integers(self, low: int, high: int | None = None) -> int:
        """A uniform integer in [low, high), or in [0, low) when ``high`` is None."""
        if high is None:
            low, high = 0, low
        if high <= low:
            raise ValueError(f"integers: empty range [{low}, {high})")
        return low + int(self.random() * (high - low))


@DETECTORS.register("oracle")
class OracleDetector:
    """Ground-truth detector with a seeded noise model (see ``OracleConfig``).

    instance_categories: simulator instance id -> category (``House.instance_categories``);
    ids not in it (walls, floor) are never reported. Noise draws depend only on
    (seed, frame.seq, instance id), so the same frame gives the same detections.
    """

    name = "oracle"

    def __init__(
        self, instance_categories: dict[int, str], config: OracleConfig | None = None, seed: int = 0
    ) -> None:
        self.config = config or OracleConfig()
        self.seed = int(seed)
        self.instance_categories = {int(k): normalise_label(v) for k, v in instance_categories.items()}
        table = dict(DEFAULT_CONFUSIONS)
        for k, v in self.config.extra_confusions.items():
            table[k] = tuple(table.get(k, ())) + tuple(v)
        self.confusions = _closure(table)
        max_id = max(self.instance_categories, default=-1)
        # lookup table instance id -> is an object (ids are small ints in the simulator)
        self._is_object = np.zeros(max(max_id + 2, 1), dtype=bool)
        for k in self.instance_categories:
            if k >= 0:
                self._is_object[k + 1] = True
        # label k + 1 -> itself for object instances, else 0 (background); one extra 0 entry at the
        # end so that np.take(..., mode="clip") sends out-of-range labels to the background
        n_lab = self._is_object.size
        self._label_lut = np.concatenate(
            [np.where(self._is_object, np.arange(n_lab), 0), [0]]
        ).astype(np.int32)
        c = self.config
        log.info(
            "OracleDetector in use (source='oracle'): detections come from the simulator's "
            "ground-truth instance channel with miss_rate=%.2f, false_positive_rate=%.2f, "
            "confusion_rate=%.2f, min_pixel_area=%d, seed=%d",
            c.miss_rate,
            c.false_positive_rate,
            c.confusion_rate,
            c.min_pixel_area,
            self.seed,
        )

    # ------------------------------------------------------------------ helpers
    def _rng(self, seq: int, key: int) -> CounterDraws:
        return CounterDraws(self.seed, int(seq), int(key))

    @staticmethod
    def _vocab_map(vocabulary: Sequence[str]) -> dict[str, str] | None:
        """Normalised label -> the caller's own word; None means accept every label."""
        if not vocabulary:
            return None
        return {normalise_label(v): v for v in vocabulary}

    # ------------------------------------------------------------------ API
    def detect(self, frame: Frame, vocabulary: Sequence[str] = ()) -> list[Detection]:
        """Detections (source "oracle") of the objects visible in ``frame``.

        frame.instances: (H, W) int instance ids (-1 none). Objects farther than any mapping
        range are still reported: the 2D image sees them. Returned labels use the caller's
        vocabulary words when a vocabulary is given.
        """
        inst = frame.instances
        if inst is None:
            raise FrameError(
                "OracleDetector needs Frame.instances (the simulator's instance channel)",
                field="frame.instances",
            )
        inst = np.asarray(inst)
        if inst.ndim != 2:
            raise FrameError(f"instances must be (H, W), got {inst.shape}", field="frame.instances")
        if frame.rgb is not None and np.asarray(frame.rgb).shape[:2] != inst.shape:
            raise FrameError(
                f"instances {inst.shape} and rgb {np.asarray(frame.rgb).shape[:2]} differ",
                field="frame.instances",
            )
        cfg = self.config
        vocab = self._vocab_map(vocabulary)
        h, w = inst.shape
        # find the objects on a 2x subsampled image (4x fewer pixels), then refine each box and mask
        # at full resolution inside its coarse box grown by the subsampling step
        step = 2
        # instance k -> label k + 1; none (-1), non-objects and out-of-range ids -> 0 (background)
        labels = self._label_lut.take(inst[::step, ::step].astype(np.int32) + 1, mode="clip")
        slices = ndimage.find_objects(labels)
        out: list[Detection] = []
        present: set[str] = set()
        for lab_minus1, sl in enumerate(slices):
            if sl is None:
                continue
            iid = lab_minus1  # label k + 1 <-> instance k
            category = self.instance_categories.get(iid)
            if category is None:
                continue
            r0, r1 = max(0, sl[0].start * step - step), min(h, sl[0].stop * step + step)
            c0, c1 = max(0, sl[1].start * step - step), min(w, sl[1].stop * step + step)
            win = inst[r0:r1, c0:c1] == iid
            area = int(np.count_nonzero(win))
            if area < cfg.min_pixel_area:
                continue
            present.add(category)
            rng = self._rng(frame.seq, iid + 1)
            u_miss, u_conf, u_pick, u_score = rng.random(4)
            if u_miss < cfg.miss_rate:
                continue
            label = category
            confused = False
            similar = self.confusions.get(category, ())
            if similar and u_conf < cfg.confusion_rate:
                label = similar[int(u_pick * len(similar)) % len(similar)]
                confused = True
            if vocab is not None and label not in vocab:
                continue
            # larger (closer, less occluded) objects get higher scores; confusions score lower
            size_factor = min(1.0, 0.6 + 0.4 * area / (0.02 * h * w))
            score = (cfg.score_min + (cfg.score_max - cfg.score_min) * u_score) * size_factor
            if confused:
                score *= 0.8
            rows = np.flatnonzero(win.any(axis=1))
            cols = np.flatnonzero(win.any(axis=0))
            box = np.array(
                [c0 + cols[0], r0 + rows[0], c0 + cols[-1] + 1, r0 + rows[-1] + 1], dtype=np.float32
            )
            mask = None
            if cfg.masks:
                mask = np.zeros((h, w), dtype=bool)
                mask[r0:r1, c0:c1] = win
            out.append(
                Detection(
                    label=vocab[label] if vocab else label,
                    score=float(score),
                    box_xyxy=box,
                    mask=mask,
                    source="oracle",
                    instance_id=iid,
                )
            )
        fp = self._false_positive(frame, vocab, present, h, w)
        if fp is not None:
            out.append(fp)
        out.sort(key=lambda d: -d.score)
        return out

    def _false_positive(
        self, frame: Frame, vocab: dict[str, str] | None, present: set[str], h: int, w: int
    ) -> Detection | None:
        """At most one spurious box per frame with a plausible label not visible in the frame."""
        cfg = self.config
        rng = self._rng(frame.seq, 0)
        if rng.random() >= cfg.false_positive_rate:
            return None
        if vocab is not None:
            candidates = sorted(k for k in vocab if k not in present)
        else:
            candidates = sorted({c for c in self.instance_categories.values()} - present)
        if not candidates:
            return None
        label = candidates[int(rng.integers(len(candidates)))]
        bw = int(rng.integers(max(8, w // 16), max(9, w // 3)))
        bh = int(rng.integers(max(8, h // 16), max(9, h // 3)))
        x0 = int(rng.integers(0, max(1, w - bw)))
        y0 = int(rng.integers(h // 4, max(h // 4 + 1, h - bh)))  # lower part: on furniture/floor
        box = np.array([x0, y0, min(w, x0 + bw), min(h, y0 + bh)], dtype=np.float32)
        score = float(cfg.score_min + (cfg.score_max - cfg.score_min) * 0.6 * rng.random())
        mask = None
        if cfg.masks:
            mask = np.zeros((h, w), dtype=bool)
            mask[y0 : y0 + bh, x0 : x0 + bw] = True
        return Detection(
            label=vocab[label] if vocab else label,
            score=score,
            box_xyxy=box,
            mask=mask,
            source="oracle",
            instance_id=None,
        )
