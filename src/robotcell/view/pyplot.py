"""matplotlib's pyplot for the figures of the reports and the reachability map: drawn off screen.

matplotlib keeps its settings and its font cache in a folder of the user's (``MPLCONFIGDIR``, else
``$XDG_CONFIG_HOME/matplotlib`` or ``~/.config/matplotlib`` on Linux). A user without a writable
home (a service account, a container run as another user) has none: matplotlib then works in a
temporary folder, deleted at exit, and logs three lines on stderr recommending ``MPLCONFIGDIR``.
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


def pyplot() -> Any:
    """``matplotlib.pyplot`` with the Agg backend (PNG in memory, no display needed).

    Returns
    -------
    module
        ``matplotlib.pyplot``. matplotlib's notes that its settings folder cannot be written are
        dropped (it uses a temporary folder then); its other messages are kept.
    """
    log = logging.getLogger("matplotlib")
    if _not_about_the_config_folder not in log.filters:
        log.addFilter(_not_about_the_config_folder)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
