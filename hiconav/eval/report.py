"""report.md and PNG plots of a benchmark run, laid out like the paper's tables.

Sections: main results per preset (SR, SPL, DTS), ablations (paired deltas against the full
method, with sign and size), failure taxonomy, efficiency (seconds per frame of each layer,
task time in stepped time, step speed, VLM calls), success by target category; plots: success by
target category, SPL histogram, failure breakdown, per-layer latency, linked from report.md.
Wherever the oracle detector or the offline reasoner was used, the report says so.

Plots use matplotlib's Agg canvas directly (no pyplot, no global backend change, no display).
This module must not run episodes or change records.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hiconav.eval.presets import DESCRIPTIONS
from hiconav.eval.records import EpisodeRecord
from hiconav.eval.taxonomy import CATEGORIES

PLOTS = {
    "success_by_target": "success_by_target.png",
    "spl_hist": "spl_hist.png",
    "failures": "failures.png",
    "layer_latency": "layer_latency.png",
}


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{100.0 * value:.1f}"


def _num(value: float | None, digits: int = 2) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def _interval(value: float | None, ci: Sequence[float] | None) -> str:
    """"63.6 [53.8, 72.5]": a percentage and its 95% interval."""
    if ci is None:
        return _pct(value)
    return f"{_pct(value)} [{_pct(ci[0])}, {_pct(ci[1])}]"


def _signed(value: float | None) -> str:
    return "-" if value is None else f"{100.0 * value:+.1f}"


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return lines + [""]


def component_labels(names: Sequence[str], kind: str) -> str:
    """'oracle detector' / 'offline reasoner' labels, spelled out wherever they were used."""
    if not names:
        return f"(no {kind} named)"
    return ", ".join(f"{name} {kind}" for name in names)


def render_markdown(records: Sequence[EpisodeRecord], summary: dict[str, Any],
                    run_info: dict[str, Any] | None = None, plots: dict[str, str] | None = None) -> str:
    presets: dict[str, dict[str, Any]] = summary.get("presets", {})
    main = summary.get("preset")
    lines = ["# hiconav evaluation report", ""]
    detectors = sorted({d for p in presets.values() for d in p["detectors"]})
    reasoners = sorted({r for p in presets.values() for r in p["reasoners"]})
    lines += [f"- Perception: {component_labels(detectors, 'detector')}",
              f"- Reasoning: {component_labels(reasoners, 'reasoner')}"]
    if "oracle" in detectors:
        lines.append("- Results use the **oracle detector** (simulator instance ids with noise), "
                     "not a learned detector.")
    if "offline" in reasoners:
        lines.append("- Results use the **offline reasoner** (no VLM was called).")
    for key, value in (run_info or {}).items():
        if value not in (None, ""):
            lines.append(f"- {key}: `{value}`")
    lines += ["", "## Main results", ""]
    rows = []
    for name, group in presets.items():
        rows.append([name, DESCRIPTIONS.get(name, name), str(group["episodes"]), str(group["valid_episodes"]),
                     _interval(group["success_rate"], group.get("success_rate_ci95")),
                     _interval(group["spl"], group.get("spl_ci95")), _num(group["dts"]),
                     ", ".join(group["detectors"]) or "-", ", ".join(group["reasoners"]) or "-"])
    lines += _table(["Preset", "Method", "Episodes", "Valid", "SR (%) [95% CI]", "SPL (%) [95% CI]", "DTS (m)",
                     "Detector", "Reasoner"], rows)
    lines += [("SR and SPL over valid episodes (invalid input is counted but not run); SPL's shortest path "
               "is the geodesic distance from the start to the success region (runs recorded before "
               "December 2026 measured it to the goal object; `python -m hiconav.eval.rescore OUT` "
               "rescores them); DTS is the mean geodesic distance to the success region at the end. "
               "Intervals: Wilson score for SR, a seeded percentile bootstrap for SPL; "
               "`python -m hiconav.eval.compare BEFORE AFTER` compares two runs episode by episode."), ""]
    semexp = [f"{name} {_pct(g['spl_semexp_code'])}% over {g['spl_semexp_code_episodes']}"
              for name, g in presets.items() if g.get("spl_semexp_code") is not None]
    if semexp:
        lines += [("On SemExp's maps (Gibson), SPL as SemExp's and L3MVN's own code computes it, for comparison "
                   "with published tables only: " + "; ".join(semexp) + " episodes. Their shortest path adds the "
                   "1.0 m success distance to the distance to the success region (docs/evaluation.md); "
                   "the SPL above does not."), ""]

    ablations: dict[str, dict[str, Any]] = summary.get("ablations", {})
    lines += ["## Ablations", ""]
    if ablations:
        rows = [[DESCRIPTIONS.get(main, str(main)) + " (reference)", "-",
                 _pct(next(iter(ablations.values()))["reference_success_rate"]),
                 _pct(next(iter(ablations.values()))["reference_spl"]), "", "", "", ""]]
        for name, delta in ablations.items():
            p = delta.get("sign_test_p")
            rows.append([DESCRIPTIONS.get(name, name), str(delta["paired_episodes"]),
                         _pct(delta["success_rate"]), _pct(delta["spl"]),
                         _signed(delta["delta_success_rate"]), _signed(delta["delta_spl"]),
                         f"{delta.get('up', '-')} / {delta.get('down', '-')}", "-" if p is None else f"{p:.3f}"])
        lines += _table(["Method", "Paired episodes", "SR (%)", "SPL (%)", "dSR (pts)", "dSPL (pts)",
                         "up / down", "sign test p"], rows)
        lines += [f"Deltas are paired: each preset against `{main}` on the episodes both ran, same seeds; "
                  "up / down: episodes that turned into a success / out of one; the exact sign test's "
                  "p-value says how likely so lopsided a split is by chance.", ""]
    else:
        lines += ["Only one preset ran; run `--preset ablations` for this table.", ""]

    lines += ["## Failure taxonomy", ""]
    categories = list(CATEGORIES) + sorted({c for g in presets.values() for c in g["failures"]} - set(CATEGORIES))
    rows = []
    for category in categories:
        row = [category]
        for group in presets.values():
            n = group["failures"].get(category, 0)
            row.append(f"{n} ({_pct(n / group['episodes'] if group['episodes'] else None)}%)")
        rows.append(row)
    lines += _table(["Category", *presets], rows)
    lines += [("Definitions: docs/evaluation.md (success, false positive, no frontier left, stuck, "
               "step-out, invalid episode, error)."), ""]

    lines += ["## Efficiency", ""]
    layer_names = sorted({layer for g in presets.values() for layer in g["timing"]["layers"]})
    rows = []
    for name, group in presets.items():
        timing = group["timing"]
        calls = [float(r.extra.get("reasoning_calls", 0)) for r in records
                 if r.preset == name and r.failure != "invalid_episode"]
        row = [name, _num(timing["task_time_s_mean"], 1), _num(timing["step_speed_m_per_s"]),
               _num(timing["steps_mean"], 0), _num(timing["vlm_calls_mean"], 1),
               _num(sum(calls) / len(calls) if calls else None, 1),
               _num(timing["wall_time_s_mean"], 2)]
        for layer in layer_names:
            spf = timing["layers"].get(layer, {}).get("seconds_per_frame")
            row.append("-" if spf is None else f"{spf * 1000.0:.3g}")
        rows.append(row)
    lines += _table(["Preset", "Task time (s, stepped)", "Step speed (m/s)", "Steps", "VLM calls",
                     "Reasoning calls", "Wall s / episode", *[f"{layer} (ms/frame)" for layer in layer_names]], rows)
    lines += [("Layer times are wall-clock seconds per processed frame; task time is simulated "
               "(stepped-clock) time. Wall times depend on the machine and its load. On the stepped "
               "clock every reasoning call (decomposition or subgraph verification, offline or VLM) "
               "takes the modelled latency `reasoning.latency_s` +- `reasoning.latency_jitter_s` "
               "(default 2.0 +- 0.5 s, a fast hosted VLM; seeded) of robot time: a call spans the "
               "discrete actions a robot makes in that time (0.5 s each, so 4 for 2 s), which on the "
               "stepped clock's 0.1 s ticks is 0.4 s (`mission.latency_time: clock` takes it in clock "
               "seconds). Task times show what asynchrony buys (compare the sync_reasoning preset)."), ""]

    split = [(name, g["path"]) for name, g in presets.items() if g.get("path", {}).get("successes_measured")]
    if split:
        lines += ["## Where the path goes", ""]
        rows = [[name, str(p["successes_measured"]), _num(p["shortest_m"], 0), _num(p["driven_m"], 0),
                 _num(p["before_view_m"], 0), _pct(p["before_view_share"]),
                 f"{_num(p.get('after_view_m'), 0)} / {_num(p.get('after_view_shortest_m'), 0)}",
                 f"{p['failures_never_in_view']} / {p['failures_measured']}"] for name, p in split]
        lines += _table(["Preset", "Successes", "Shortest (m)", "Driven (m)", "Before the goal in view (m)",
                         "Share (%)", "After: driven / shortest (m)", "Failures never in view"], rows)
        lines += [("Over the successes: SPL's shortest paths, the path driven, and the part driven before a "
                   "goal instance first covered 150 pixels within the depth range (the simulator's ground "
                   "truth, not what the detector reported); after it, the path driven against the shortest "
                   "path from that spot to the success region. Before the view is exploration; after it, "
                   "detection, verification and the approach."), ""]
        excess = [(name, g["path"]["excess"]) for name, g in presets.items()
                  if (g.get("path") or {}).get("excess", {}).get("successes_measured")]
        lines += [f"Path beyond SPL's shortest paths, {name}: {_num(e['excess_m'], 0)} m over "
                  f"{e['successes_measured']} successes, by the behaviour whose goal each step served: " + ", ".join(
                      f"{b} {_num(v['m'], 0)} m ({_pct(v['share'])}%)" for b, v in e["by_behaviour"].items())
                  + f"; {_num(e['inside_m'], 1)} m of it inside the success region (ground truth: a step's length "
                    "less its progress toward the region)." for name, e in excess]
        acts = [(name, p) for name, p in ((n, g.get("actions", {})) for n, g in presets.items())
                if p.get("episodes_measured")]
        lines += [f"Turns in place, {name}: {p['turns']} of {p['actions']} actions ({_pct(p['turn_share'])}%) over "
                  f"{p['episodes_measured']} episodes: a turn costs a step of the budget and no path." for name, p in acts]
        lines += [f"Actions by the behaviour whose goal they served, {name}: " + ", ".join(
                  f"{b} {v['actions']} ({_pct(v['share'])}%, {v['turns']} turns)" for b, v in p["by_behaviour"].items())
                  + "." for name, p in acts if p.get("by_behaviour")]
        lines += [""] if acts else []

    if main is not None and presets.get(main, {}).get("by_target"):
        lines += [f"## Success by target category ({main})", ""]
        rows = [[t, str(v["episodes"]), _pct(v["success_rate"]), _pct(v["spl"])]
                for t, v in presets[main]["by_target"].items()]
        lines += _table(["Target", "Episodes", "SR (%)", "SPL (%)"], rows)

    errors = [r for r in records if r.error]
    if errors:
        lines += ["## Episodes with errors or invalid input", ""]
        rows = [[r.preset, r.episode_id, r.failure, (r.error or "").replace("|", "/")[:160]] for r in errors[:50]]
        lines += _table(["Preset", "Episode", "Category", "Message"], rows)
        if len(errors) > 50:
            lines += [f"... and {len(errors) - 50} more (see episodes.jsonl).", ""]

    if plots:
        lines += ["## Plots", ""]
        for title, file in plots.items():
            lines += [f"![{title}]({file})", ""]
    return "\n".join(lines)


def _legend(ax: Any, **options: Any) -> None:
    """A legend only when something on ``ax`` has a label (else matplotlib warns "No artists
    with labels found to put in legend")."""
    handles, _ = ax.get_legend_handles_labels()
    if handles:
        ax.legend(**options)


def write_plots(out: str | Path, records: Sequence[EpisodeRecord], summary: dict[str, Any]) -> dict[str, str]:
    """The four PNG plots in ``out``; returns {title: file name} of those written."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    out = Path(out)
    presets: dict[str, dict[str, Any]] = summary.get("presets", {})
    main = summary.get("preset")
    written: dict[str, str] = {}

    def save(fig: Figure, key: str, title: str) -> None:
        FigureCanvasAgg(fig)
        fig.tight_layout()
        fig.savefig(out / PLOTS[key], dpi=110)
        written[title] = PLOTS[key]

    if main is not None and main in presets:
        by_target = presets[main]["by_target"]
        fig = Figure(figsize=(max(4.0, 0.6 * len(by_target) + 2), 3.2))
        ax = fig.add_subplot()
        names = list(by_target)
        ax.bar(names, [100.0 * (by_target[t]["success_rate"] or 0.0) for t in names], color="#4c72b0")
        ax.set_ylabel("success rate (%)")
        ax.set_ylim(0, 100)
        ax.set_title(f"Success by target category ({main})")
        ax.tick_params(axis="x", rotation=45)
        save(fig, "success_by_target", "Success by target category")

    fig = Figure(figsize=(5.0, 3.2))
    ax = fig.add_subplot()
    for name in presets:
        values = [r.spl for r in records if r.preset == name and r.failure != "invalid_episode"]
        if values:
            ax.hist(values, bins=20, range=(0.0, 1.0), histtype="step", label=name, linewidth=1.5)
    ax.set_xlabel("SPL")
    ax.set_ylabel("episodes")
    ax.set_title("SPL histogram")
    _legend(ax, fontsize=7)
    save(fig, "spl_hist", "SPL histogram")

    fig = Figure(figsize=(max(5.0, 1.0 * len(presets) + 3), 3.4))
    ax = fig.add_subplot()
    names = list(presets)
    bottoms = [0.0] * len(names)
    for category in CATEGORIES:
        heights = [100.0 * presets[p]["failure_rates"].get(category, 0.0) for p in names]
        if any(heights):
            ax.bar(names, heights, bottom=bottoms, label=category)
            bottoms = [b + h for b, h in zip(bottoms, heights)]
    ax.set_ylabel("episodes (%)")
    ax.set_title("Outcome breakdown (failure taxonomy)")
    ax.tick_params(axis="x", rotation=30)
    _legend(ax, fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    save(fig, "failures", "Failure breakdown")

    layers = presets.get(main, {}).get("timing", {}).get("layers", {}) if main else {}
    fig = Figure(figsize=(5.0, 3.2))
    ax = fig.add_subplot()
    names = [n for n, v in layers.items() if v["seconds_per_frame"] is not None]
    ax.barh(names, [1000.0 * layers[n]["seconds_per_frame"] for n in names], color="#dd8452")
    ax.set_xlabel("ms per frame (wall clock)")
    ax.set_title(f"Per-layer latency ({main})")
    save(fig, "layer_latency", "Per-layer latency")
    return written


def write_report(out: str | Path, records: Sequence[EpisodeRecord], summary: dict[str, Any],
                 run_info: dict[str, Any] | None = None) -> Path:
    """Write the plots and ``report.md`` into ``out``; returns the report's path."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    plots = write_plots(out, records, summary)
    path = out / "report.md"
    path.write_text(render_markdown(records, summary, run_info, plots), encoding="utf-8")
    return path
