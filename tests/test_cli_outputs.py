"""Output files of the command line: checked before any work starts, committed together or not at all.

`plansim run --out/--plot` and `plansim record --out`: an existing folder, a missing folder or a folder
that cannot be written is an error (exit status 2, ``plansim: error: …`` naming the option and the path)
before the simulation, and nothing is written. The outputs of one command go to temporary files beside
their targets and are renamed onto them only once all are complete (:class:`plansim.io.files.OutputSet`).
"""

from __future__ import annotations

import os
import tempfile

import pytest

import plansim.report.plot
import plansim.runner
from plansim.cli import main
from plansim.io.files import OutputSet, check_output_path


def run_cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _fails_if_called(*args, **kwargs):
    raise AssertionError("the simulation started although an output could not be written")


@pytest.fixture
def no_simulation(monkeypatch):
    """Make every entry into the simulation fail the test: the checks must come first."""
    for name in ("run", "run_summary", "simulate_and_record"):
        monkeypatch.setattr(plansim.runner, name, _fails_if_called)


@pytest.fixture
def unwritable_folder(tmp_path):
    """A folder in which this process cannot create a file (a read-only folder; for root, /sys)."""
    folder = tmp_path / "read-only"
    folder.mkdir()
    folder.chmod(0o555)
    candidates = [folder, "/sys"]
    try:
        for candidate in candidates:
            try:
                fd, probe = tempfile.mkstemp(dir=candidate)
            except OSError:
                yield str(candidate)
                return
            os.close(fd)
            os.remove(probe)
        pytest.skip("no folder here refuses a new file to this process")
    finally:
        folder.chmod(0o755)


def _listing(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


# ----------------------------------------------------------------------------- checked before any work

@pytest.mark.parametrize("option", ["--out", "--plot"])
def test_run_refuses_an_existing_folder_as_output_before_simulating(capsys, tmp_path, monkeypatch, no_simulation,
                                                                    option):
    monkeypatch.chdir(tmp_path)
    name = "results.nc" if option == "--out" else "figure.png"
    (tmp_path / name).mkdir()
    code, out, err = run_cli(capsys, "run", "ideal", "--trials", "3", option, name, "--quiet")
    assert code == 2, err
    assert err.startswith("plansim: error:") and option in err and repr(name) in err and "is a folder" in err
    assert out == "" and _listing(tmp_path) == [name] and list((tmp_path / name).iterdir()) == []


@pytest.mark.parametrize("option, name", [("--out", "missing/r.nc"), ("--plot", "missing/f.png")])
def test_run_refuses_a_missing_folder_before_simulating(capsys, tmp_path, monkeypatch, no_simulation, option, name):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(capsys, "run", "ideal", "--trials", "3", option, name, "--quiet")
    assert code == 2 and option in err and repr(name) in err and "does not exist" in err
    assert _listing(tmp_path) == []


@pytest.mark.parametrize("option, name", [("--out", "r.nc"), ("--plot", "f.png")])
def test_run_refuses_an_unwritable_folder_before_simulating(capsys, tmp_path, monkeypatch, no_simulation,
                                                            unwritable_folder, option, name):
    monkeypatch.chdir(tmp_path)
    target = os.path.join(unwritable_folder, name)
    code, _, err = run_cli(capsys, "run", "ideal", "--trials", "3", option, target, "--quiet")
    assert code == 2, err
    assert err.startswith("plansim: error:") and option in err and repr(target) in err and "cannot write" in err


def test_a_folder_that_is_a_file_is_refused(capsys, tmp_path, monkeypatch, no_simulation):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "notes.txt").write_text("x")
    code, _, err = run_cli(capsys, "run", "ideal", "--out", "notes.txt/r.nc", "--quiet")
    assert code == 2 and "--out" in err and "is not a folder" in err
    assert _listing(tmp_path) == ["notes.txt"]


def test_plot_with_one_trial_is_refused_before_simulating_and_writes_nothing(capsys, tmp_path, monkeypatch,
                                                                              no_simulation):
    """Today's defect: `--trials 1 --out r.nc --plot f.png` exited 2 after writing r.nc."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, "run", "ideal", "--trials", "1", "--out", "r.nc", "--plot", "f.png", "--quiet")
    assert code == 2 and "--plot" in err and "at least 2 trials" in err
    assert out == "" and _listing(tmp_path) == []


def test_the_same_file_twice_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with OutputSet() as outputs:
        outputs.stage("r.nc", "--out")
        with pytest.raises(ValueError, match=r"--again '\./r\.nc': this file is already the output of --out"):
            outputs.stage("./r.nc", "--again")
    assert _listing(tmp_path) == []


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_record_refuses_an_existing_folder_before_simulating(capsys, tmp_path, monkeypatch, no_simulation, suffix):
    monkeypatch.chdir(tmp_path)
    (tmp_path / f"rec{suffix}").mkdir()
    code, _, err = run_cli(capsys, "record", "ideal", "--out", f"rec{suffix}")
    assert code == 2, err
    assert err.startswith("plansim: error:") and "--out" in err and f"'rec{suffix}'" in err and "is a folder" in err


def test_record_refuses_a_csv_whose_segment_table_would_be_a_folder(capsys, tmp_path, monkeypatch, no_simulation):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "rec.segments.csv").mkdir()
    code, _, err = run_cli(capsys, "record", "ideal", "--out", "rec.csv")
    assert code == 2 and "'rec.segments.csv'" in err and "is a folder" in err
    assert _listing(tmp_path) == ["rec.segments.csv"]


def test_record_refuses_an_unwritable_folder_before_simulating(capsys, no_simulation, unwritable_folder):
    target = os.path.join(unwritable_folder, "rec.nc")
    code, _, err = run_cli(capsys, "record", "ideal", "--out", target)
    assert code == 2 and "--out" in err and repr(target) in err and "cannot write" in err


# ----------------------------------------------------------------------------- all or none

def _plot_fails(exception):
    def fail(results, scenario, comparisons, path, **kwargs):
        with open(path, "wb") as fh:  # a part of the figure is written, then the writer fails
            fh.write(b"\x89PNG")
        raise exception
    return fail


@pytest.mark.parametrize("exception, code", [(ValueError("no figure today"), 2), (KeyboardInterrupt(), 130)])
def test_a_failing_figure_leaves_no_results_file(capsys, tmp_path, monkeypatch, exception, code):
    """--out and --plot are committed together: when the figure fails, the results file is not kept either."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(plansim.report.plot, "appendix_a_histograms", _plot_fails(exception))
    got, out, err = run_cli(capsys, "run", "ideal", "--trials", "3", "--out", "r.nc", "--plot", "f.png", "--quiet")
    assert got == code, err
    assert _listing(tmp_path) == []


def test_existing_outputs_stay_as_they_were_when_the_command_fails(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "r.nc").write_bytes(b"old results")
    (tmp_path / "f.png").write_bytes(b"old figure")
    monkeypatch.setattr(plansim.report.plot, "appendix_a_histograms", _plot_fails(ValueError("no figure")))
    code, _, _ = run_cli(capsys, "run", "ideal", "--trials", "3", "--out", "r.nc", "--plot", "f.png", "--quiet")
    assert code == 2
    assert (tmp_path / "r.nc").read_bytes() == b"old results" and (tmp_path / "f.png").read_bytes() == b"old figure"
    assert _listing(tmp_path) == ["f.png", "r.nc"]


def test_existing_output_files_are_replaced_with_ordinary_permissions(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "r.nc").write_bytes(b"old results")
    code, out, err = run_cli(capsys, "run", "ideal", "--trials", "3", "--out", "r.nc", "--plot", "f.png", "--quiet")
    assert code == 0, err
    assert (tmp_path / "r.nc").read_bytes()[:4] != b"old " and (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"
    umask = os.umask(0)
    os.umask(umask)
    assert (tmp_path / "f.png").stat().st_mode & 0o777 == 0o666 & ~umask
    assert _listing(tmp_path) == ["f.png", "r.nc"]
    assert "wrote results: r.nc" in out and "wrote figure: f.png" in out


# ----------------------------------------------------------------------------- OutputSet itself

def test_output_set_commits_every_file_or_none(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    with OutputSet() as outputs:
        tmp_a, tmp_b = outputs.stage(a, "A"), outputs.stage(b, "B")
        assert os.path.dirname(tmp_a) == str(tmp_path) and os.path.basename(tmp_a).startswith(".a.txt.")
        assert tmp_a.endswith(".part") and not a.exists()
        for tmp, text in ((tmp_a, "a"), (tmp_b, "b")):
            with open(tmp, "w") as fh:
                fh.write(text)
        outputs.commit()
    assert a.read_text() == "a" and b.read_text() == "b" and _listing(tmp_path) == ["a.txt", "b.txt"]

    with pytest.raises(KeyboardInterrupt), OutputSet() as outputs:
        with open(outputs.stage(a, "A"), "w") as fh:
            fh.write("new a")
        outputs.stage(b, "B")
        raise KeyboardInterrupt
    assert a.read_text() == "a" and _listing(tmp_path) == ["a.txt", "b.txt"]

    with OutputSet() as outputs:  # left without a commit: nothing changes either
        outputs.stage(tmp_path / "c.txt", "C")
    assert _listing(tmp_path) == ["a.txt", "b.txt"]


def test_output_set_undoes_its_new_files_when_a_rename_fails(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    with OutputSet() as outputs:
        for target in (a, b):
            with open(outputs.stage(target, "X"), "w") as fh:
                fh.write("new")
        b.mkdir()  # the folder changed under the command after the check
        with pytest.raises(ValueError, match=r"X '.*b\.txt'.*is a folder"):
            outputs.commit()
    assert _listing(tmp_path) == ["b.txt"] and b.is_dir()


def test_check_output_path_names_the_option_the_path_and_what_is_allowed(tmp_path):
    with pytest.raises(ValueError, match=r"--out '.*r\.txt': the file name must end in \.nc"):
        check_output_path(tmp_path / "r.txt", "--out", (".nc",))
    assert check_output_path(tmp_path / "r.NC", "--out", (".nc",)) == tmp_path / "r.NC"
    with pytest.raises(ValueError, match="--out '': no file name"):
        check_output_path("", "--out")
    assert _listing(tmp_path) == []
