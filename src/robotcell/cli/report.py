"""``robotcell report``: an HTML report with figures from a calibration result."""

from __future__ import annotations

import click

from robotcell.cli.common import check_kind, check_not_folder
from robotcell.cli.files import OUTPUT, Command
from robotcell.report import load_result, verdict, write_report


@click.command(cls=Command)
@click.argument("result", type=click.Path())
@click.option("-o", "--output", default="report.html", show_default=True, type=OUTPUT,
              callback=check_not_folder,
              help="HTML file to write; its figures are embedded, nothing else is written.")
def report(result: str, output: str) -> None:
    """Write a self-contained HTML report, figures embedded, for a calibration result.

    RESULT is the JSON written by 'robotcell calibrate ... --json'.

    \b
    Example:
      robotcell calibrate frame base.csv --json -o base.json
      robotcell report base.json -o base.html
    """
    check_kind(output, "HTML", "the report")
    data = load_result(result)
    files = write_report(data, output)
    grade, reasons = verdict(data)
    click.echo(f"{grade.upper()}: {'; '.join(reasons)}")
    for f in files:
        click.echo(f"wrote {f}")
