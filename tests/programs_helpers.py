"""Files the tests of robotcell.programs share: the example cell and seam, RoboDK's programs."""

from pathlib import Path

TESTS = Path(__file__).resolve().parent
EXAMPLES = TESTS.parent / "examples"
#: The example cell: a KR 16 on a track beside a turntable with the frame 'part' on it.
CELL = EXAMPLES / "cell_kr16_track_turntable.yaml"
#: A seam in the frame 'part', with the table angle of each point.
SEAM = EXAMPLES / "seam_part.csv"
#: RoboDK's example station in the four formats, and cells for them (see the folder's README).
ROBODK = TESTS / "data" / "programs" / "robodk"
#: The main file of a program per format.
EXT = {"kuka": ".src", "abb": ".mod", "fanuc": ".ls", "yaskawa": ".jbi"}


def write_mutation(path: Path, content: str | bytes) -> None:
    """Write a mutated file's content (text with lone surrogates kept, or bytes)."""
    path.write_bytes(content if isinstance(content, bytes) else content.encode(
        "utf-8", errors="surrogatepass"))


def mutated_program(src: Path, case: Path, rng) -> str:
    """Copy the files of the program ``src`` into the new folder ``case`` and mutate one of them
    (a KUKA program's .src or .dat); return what the mutation was."""
    from test_cli_fuzz import mutate_text

    case.mkdir()
    for f in src.parent.iterdir():
        (case / f.name).write_bytes(f.read_bytes())
    target = case / (src.with_suffix(".dat").name if src.suffix == ".src" and rng.random() < 0.5
                     else src.name)
    content, what = mutate_text(target.read_text(), rng)
    write_mutation(target, content)
    return what


def outcome_problems(code: int, stdout: str, err: str, left_files: bool) -> list[str]:
    """What is wrong with a fuzzed run: an undocumented status, a traceback, an exit 2 without
    one ``error:`` line, or files left by a refused run (``left_files``)."""
    problems = []
    if code not in (0, 2, 3):
        problems.append(f"exit {code}")
    if "Traceback" in stdout + err:
        problems.append("traceback")
    if code == 2 and err.count("error:") != 1:
        problems.append("exit 2 without one 'error:' line")
    if code in (2, 3) and left_files:
        problems.append("a refused run left files")
    return problems
