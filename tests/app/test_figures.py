"""The report's figure list names exactly the files a run wrote (issue 27, point 7), and
the study figures leave out what has nothing to draw and say so."""

import numpy as np
from gearsym.solver.periodic.records import Branch, BranchPoint
from gearsym.studies import figures
from gearsym.studies.figures import figure_list


def _touch(folder, *names):
    for name in names:
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(b"\x89PNG")


def test_figure_list_names_the_files_present_and_only_those(tmp_path):
    _touch(tmp_path, "bifurcation_light.png", "sensitivity/light-a-b-motion.png", "extra.png")
    captions = [
        ("bifurcation_*.png", "diagrams"),
        ("map_f1_lambda.png", "a map this run did not write"),
        ("sensitivity/*-motion.png", "motion maps"),
    ]
    text = figure_list(tmp_path, captions)
    assert text.splitlines() == [
        "- `bifurcation_light.png`: diagrams",
        "- `sensitivity/light-a-b-motion.png`: motion maps",
        "- `extra.png`: (no caption)",
    ]
    assert "map_f1_lambda" not in text
    assert figure_list(tmp_path / "none") == "(no figures were written)"


def test_default_captions_cover_what_reproduce_writes(tmp_path):
    written = [
        "bifurcation_heavy.png",
        "point_light_lambda_0.8.png",
        "map_f1_lambda.png",
        "continuation_light.png",
        "floquet_light.png",
        "meshing_lyapunov_light.png",
        "response_light.png",
        "backlash.png",
        "stiffness.png",
        "bearings_lambda.png",
        "sensitivity/light-q-braking-te_amplitude_um-attractors.png",
    ]
    _touch(tmp_path, *written)
    text = figure_list(tmp_path)
    assert "(no caption)" not in text
    assert all(f"`{name}`" in text for name in written)
    line = next(s for s in text.splitlines() if "attractors" in s)
    assert "every attractor counted" in line  # not the dominant attractor's caption


def _branch(values):
    pts = tuple(
        BranchPoint(v, np.zeros(4), np.array([0.6, 0.2]), True, "stable", 1) for v in values
    )
    return Branch("lambda", 1, pts, state_names=("u", "v", "du", "dv"))


def test_floquet_figure_skips_a_branch_without_extent_and_says_so(tmp_path, monkeypatch):
    seen = []
    original = figures._save

    def save(fig, path):
        seen.append(fig.axes[0].get_title())
        return original(fig, path)

    monkeypatch.setattr(figures, "_save", save)
    path = figures.floquet_figure(
        [_branch([0.0, 0.5, 1.0]), _branch([0.0, 0.0])], tmp_path / "f.png", "t", "c"
    )
    assert path.stat().st_size > 1000
    assert "1 branch(es) without extent in lambda not drawn" in seen[0]
