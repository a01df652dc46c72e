"""Output path checks speak of the path; the command line puts the flag name in front."""

from __future__ import annotations

from pathlib import Path

import pytest

from semexplore_gym.cli._flags import check_output_flag
from semexplore_gym.config import check_output_file


@pytest.mark.parametrize(
    ("name", "suffixes", "fragment"),
    [
        ("", (), "'' is empty; give a file path"),
        ("out.txt", (".png",), "out.txt' must end in .png"),
        ("missing/out.png", (".png",), "does not exist"),
        ("a" * 300 + ".png", (), "longer than 255 bytes"),
    ],
)
def test_errors_name_the_path_not_a_flag(
    tmp_path: Path, name: str, suffixes: tuple[str, ...], fragment: str
) -> None:
    path = str(tmp_path / name) if name else ""
    with pytest.raises(ValueError, match=fragment) as err:
        check_output_file(path, suffixes)
    assert "--" not in str(err.value)


def test_a_directory_is_refused_and_a_writable_path_passes(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="is a directory"):
        check_output_file(str(tmp_path))
    check_output_file(str(tmp_path / "x.gif"), (".gif",))
    check_output_file(str(tmp_path / "new" / "x.gif"), (".gif",), parent_must_exist=False)


def test_the_cli_helper_puts_the_flag_first(tmp_path: Path) -> None:
    with pytest.raises(ValueError) as err:
        check_output_flag("--gif", str(tmp_path / "x.txt"), (".gif",))
    assert str(err.value).startswith("--gif '") and str(err.value).endswith("must end in .gif")
