"""Describe the machine a benchmark ran on (CPU model, cores, Python and numpy versions)."""

from __future__ import annotations

import os
import platform

import numpy as np


def describe() -> str:
    """One line naming the CPU, core count, Python and numpy versions."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return (f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"numpy {np.__version__}")
