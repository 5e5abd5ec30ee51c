"""Bad input is told what to do: the keys to give, the built-in of that name, the
installed engines; a message never names an option the user did not give."""

from __future__ import annotations

import pytest

from harness.cli import main
from harness.simulators import engine_names


def error_line(argv, capsys) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    return err


def test_fidelity_on_a_full_state_scene_does_not_name_scale(capsys):
    err = error_line(["fidelity", "grazing-contact", "--engine", "linear"], capsys)
    assert "--scale" not in err
    assert err.startswith("harness: error: fidelity needs") and "q and p" in err


def test_scale_names_itself_when_given(capsys):
    err = error_line(["simulate", "grazing-contact", "--scale", "2"], capsys)
    assert "--scale needs" in err


@pytest.mark.parametrize(
    ("text", "keys"),
    [
        ('name = "x"\n[body]\nn = 3\n', ["q and p", "position", "angular_velocity"]),
        ('name = "x"\n[initial]\nq = [0, 0, 1]\np = [0, 0, 0]\n', ["n (vertices"]),
    ],
)
def test_missing_table_says_which_keys_to_give(text, keys, tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(text)
    err = error_line(["simulate", str(scene)], capsys)
    assert all(k in err for k in keys)


def test_missing_file_named_like_a_builtin_points_at_it(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    err = error_line(["simulate", "rod.toml"], capsys)
    assert "built-in scene is named 'rod'" in err


def test_missing_file_is_said_once(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert error_line(["simulate", "nothere.toml"], capsys).count("not found") == 1


def test_compare_without_engine_lists_the_installed_ones(capsys):
    err = error_line(["compare", "rod"], capsys)
    assert "--engine" in err
    assert all(e in err for e in engine_names() if e != "reference")


def test_chatter_legend_describes_only_what_is_printed(capsys):
    argv = ["analyze", "chatter", "--n", "2", "--gyration", "0.3", "--restitution", "0.2"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "beta_p = " in out and "spectral radius" not in out and "table (" not in out


def test_chatter_without_self_similar_pairs_explains_no_table(capsys):
    argv = ["analyze", "chatter", "--n", "3", "--gyration", "0.3", "--restitution", "0.5"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "beta_p" not in out and "spectral radius" not in out and "CC" in out


def test_symbols_are_spelled_in_ascii_where_stdout_cannot_show_them():
    from harness.text import terminal_safe

    text = "ρ = 0.3, γ = 0.5, Δ/a ≈ 2e-3, ε² – 1"
    assert terminal_safe(text, "utf-8") == text
    assert terminal_safe(text, "ascii") == "rho = 0.3, gamma = 0.5, Delta/a ~ 2e-3, eps^2 - 1"


def test_simulate_says_it_was_scaled_and_names_both_files_it_writes(tmp_path, capsys):
    out = tmp_path / "run.parquet"
    assert main(["simulate", "pentagon-bounce", "--scale", "1e-4", "--out", str(out)]) == 0
    stdout, stderr = capsys.readouterr()
    assert "scaled      by ε = 0.0001: q × ε² = 1e-08, p × ε = 0.0001" in stdout
    assert f"wrote {out} (samples) and {tmp_path / 'run.impacts.parquet'} (impacts)" in stderr


def test_branches_names_contacts_as_the_tables_do(capsys):
    import re

    assert main(["branches", "triangle-chatter"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"t_u = \S+ s, contacts v\d, v\d\n", out), out
    moreau = next(line for line in out.splitlines() if line.startswith("moreau "))
    # at t_u, E after, next at (a contact), next in [s] (a number): one value a cell
    assert re.search(r" v\d v\d +\S+ +v\d +[0-9.e+-]+ +singularity ", moreau), moreau
    assert max(len(line) for line in out.splitlines()) <= 100
