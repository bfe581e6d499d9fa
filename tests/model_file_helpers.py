"""The size of what a model or cell file holds, for the tests of every writer of model files."""

from pathlib import Path

from robotcell.io.yamlfile import parse_yaml

#: Statistics, not constants: covariances (mm^2, ...) and their sources.
STATISTICS = {"covariance", "covariance_mm_rad", "sources_mm_rad", "sigma"}


def read(path: Path):
    """The parsed content of a YAML file."""
    return parse_yaml(Path(path).read_text(encoding="utf-8"), str(path))


def largest_number(data) -> float:
    """The largest number the parsed content of a model or cell file holds, statistics aside.

    Lengths are in mm and angles in degrees (limits of at most 1000 rad, 57296 degrees), so a
    largest number of at most 1e5 says no length reaches beyond 100 m.
    """
    return max(_numbers(data), default=0.0)


def _numbers(value):
    if isinstance(value, dict):
        for k, v in value.items():
            if k not in STATISTICS:
                yield from _numbers(v)
    elif isinstance(value, list):
        for v in value:
            yield from _numbers(v)
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield abs(float(value))
