"""The Figure 11 / Figure 12 analogues of the paper (METHOD.md section 7), drawn from a run trace.

Rows over time, phases shaded and labelled: the constraint-based force's computation
time (us, per haptic tick), the god-object update time (ms, per sim step), the number of
contacts (per sim step), and components of the force sent to the user (N): Y and Z as the
paper's figures show them, or the ones asked for (`gauss6 run`: X, Y and Z).
"""
from __future__ import annotations

from pathlib import Path


def phase_spans(trace, end_time: float) -> list[tuple[str, float, float]]:
    """(name, start, end) of each phase from the trace's metadata (its phase events mark the same starts)."""
    phases = [(p["name"], float(p["start"])) for p in trace.meta.get("phases", [])]
    return [(name, start, phases[i + 1][1] if i + 1 < len(phases) else end_time)
            for i, (name, start) in enumerate(phases)]


def plot_run(trace, title: str, out_stem: Path, let_go_time: float | None = None, force_axes: str = "YZ") -> list[Path]:
    """Writes out_stem.png and out_stem.svg; returns their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ticks, steps = trace.ticks, trace.steps
    t_end = float(ticks["t"][-1]) if len(ticks) else 0.0
    rows = [
        ("force time (us)", ticks["t"], ticks["force_time"] * 1e6, "C0"),
        ("god-object update (ms)", steps["t"], steps["update_time"] * 1e3, "C1"),
        ("contacts", steps["t"], steps["num_contacts"], "C2"),
        *[(f"force {axis} (N)", ticks["t"], ticks["wrench"][:, "XYZ".index(axis)], {"X": "C5", "Y": "C3", "Z": "C4"}[axis])
          for axis in force_axes],
    ]
    fig, axes = plt.subplots(len(rows), 1, figsize=(10, 1.9 * len(rows)), sharex=True)
    spans = phase_spans(trace, t_end)
    for ax, (label, t, y, color) in zip(axes, rows):
        for i, (_, start, end) in enumerate(spans):
            ax.axvspan(start, end, color="0.92" if i % 2 == 0 else "white", zorder=0)
        if label.startswith("force time") or label.startswith("god-object"):
            ax.plot(t, y, ".", ms=1.5, color=color)
            ax.set_yscale("log")
        elif label == "contacts":
            ax.step(t, y, where="post", lw=0.8, color=color)
        else:
            ax.plot(t, y, lw=0.8, color=color)
            ax.axhline(0, color="0.5", lw=0.5)
        if let_go_time is not None and let_go_time >= 0:
            ax.axvline(let_go_time, color="k", ls="--", lw=0.8)
        ax.set_ylabel(label, fontsize=9)
        ax.grid(True, alpha=0.3)
    for name, start, end in spans:
        axes[0].text(0.5 * (start + end), 1.02, f"({name})" if len(name) == 1 else name,
                     transform=axes[0].get_xaxis_transform(), ha="center", va="bottom", fontsize=10)
    if let_go_time is not None and let_go_time >= 0:
        axes[-1].text(let_go_time, 0.02, " let go", transform=axes[-1].get_xaxis_transform(), fontsize=8)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(title, y=0.995)
    fig.tight_layout()
    out_stem = Path(out_stem)
    paths = [out_stem.with_suffix(".png"), out_stem.with_suffix(".svg")]
    fig.savefig(paths[0], dpi=130)
    fig.savefig(paths[1])
    plt.close(fig)
    return paths
