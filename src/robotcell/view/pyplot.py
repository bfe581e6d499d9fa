"""matplotlib's pyplot for the figures of the reports and the reachability map: drawn off screen.

matplotlib keeps its settings and its font cache in a folder of the user's (``MPLCONFIGDIR``, else
``$XDG_CONFIG_HOME/matplotlib`` or ``~/.config/matplotlib`` on Linux). A user without a writable
home (a service account, a container run as another user) has none: matplotlib then works in a
temporary folder, deleted at exit, and logs three lines on stderr recommending ``MPLCONFIGDIR`` (and, when building its font
cache there takes more than 5 s, a fourth).
robotcell keeps the temporary folder and drops those lines (docs/performance.md, "A read-only
install"), as it compiles its kernels in memory where numba cannot cache them: a command's
output is the same with and without a writable home.
"""

from __future__ import annotations

import logging
from typing import Any

__all__ = ["pyplot"]


def _not_about_the_config_folder(record: logging.LogRecord) -> bool:
    """Whether a record of matplotlib's logger is other than its note on an unwritable folder."""
    return record.funcName != "_get_config_or_cache_dir"


def _not_about_the_font_cache(record: logging.LogRecord) -> bool:
    """Whether a record of matplotlib's font manager is other than its note, 5 s into building
    the font cache, that it is building it (each process does in a temporary folder)."""
    return "building the font cache" not in str(record.msg)


def pyplot() -> Any:
    """``matplotlib.pyplot`` with the Agg backend (PNG in memory, no display needed).

    Returns
    -------
    module
        ``matplotlib.pyplot``. matplotlib's notes that its settings folder cannot be written
        (it uses a temporary folder then) and that it is building its font cache there (after
        5 s, so whether it shows depends on the machine's load) are dropped; its other messages
        are kept.
    """
    for name, keep in (("matplotlib", _not_about_the_config_folder),
                       ("matplotlib.font_manager", _not_about_the_font_cache)):
        log = logging.getLogger(name)  # a logger's filters see only its own records
        if keep not in log.filters:
            log.addFilter(keep)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
