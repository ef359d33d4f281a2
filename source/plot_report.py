#!/usr/bin/env python3
"""Plot convergence histories from one or several membranes report.csv files.

Usage::

    plot_report.py [--output PREFIX] [--title T] [--svg] [--columns C1,C2,...]
                   report.csv[=LABEL] [more.csv[=LABEL] ...]

Draws one figure with two log-log panels: errors versus number of degrees of
freedom (left) and errors versus cumulative wall time (right), the time of
the method: ``cumulative_wall_time_s`` does not contain the error norms
against the exact solution (``time_errors_s``), which a run without one
never computes.  By default
every ``err_*`` column that holds values is plotted, plus ``estimator`` when
it is present and non-empty; ``--columns`` names the columns to plot instead
(e.g. ``--columns err_energy,estimator``), in the order given.  A named
column must hold drawable values in at least one report, and every report in
at least one named column.  Each quantity has its own colour, each report
file its own marker and line style; a file is labelled by LABEL if given,
otherwise by the name of the directory containing it.  Quantities whose
values coincide in every report (e.g. ``err_lambda_L2`` and
``err_lambda_L2_omega_h`` when lambda vanishes near the boundary) are drawn
once, and the legend names them together (``a = b``).  The left panel also
shows reference slopes N^{-1/2} and N^{-1} (in two dimensions h ~ N^{-1/2},
so these are the orders h and h^2).  The legend sits below the panels,
outside the data.

The figure is written to PREFIX.png (and PREFIX.svg with ``--svg``); the
default PREFIX is ``convergence`` in the directory of the first file.  The
paths written are printed.  Rows or values that cannot be drawn on
logarithmic axes (empty, zero, negative, NaN) are skipped.

Requires matplotlib; the Agg backend is used, so no display is needed.
"""

import argparse
import csv
import math
import os
import sys

PROG = "plot_report.py"
DOFS = "dofs"
TIME = "cumulative_wall_time_s"
ERROR_PREFIX = "err_"
ESTIMATOR = "estimator"

MARKERS = ["o", "s", "^", "D", "v", "P", "X", "<", ">", "*"]
LINE_STYLES = ["-", "--", ":", "-."]
# (exponent of N, legend label, dash pattern) of the reference slopes.
REFERENCE_SLOPES = [(-0.5, r"$N^{-1/2}$", (0, (6, 3))),
                    (-1.0, r"$N^{-1}$", (0, (2, 2)))]
# Relative difference up to which two quantities coincide.
COINCIDENCE = 1e-12


class PlotError(Exception):
    """An input problem worth a one-line message."""


class Series:
    """The plottable contents of one report file."""

    def __init__(self, path, label, columns):
        self.path = path
        self.label = label
        self.columns = columns  # name -> list of floats (None when empty)

    def quantities(self, selection=None):
        """The columns to draw that hold positive values: @p selection if
        given, else the error columns and the estimator."""
        if selection is None:
            names = [name for name in self.columns
                     if name.startswith(ERROR_PREFIX) or name == ESTIMATOR]
        else:
            names = selection
        return [name for name in names if self.points(DOFS, name)]

    def points(self, x_name, y_name):
        """(x, y) pairs of two columns where both are positive and finite."""
        if x_name not in self.columns or y_name not in self.columns:
            return []
        return [(x, y) for x, y in zip(self.columns[x_name],
                                       self.columns[y_name])
                if is_loggable(x) and is_loggable(y)]


def is_loggable(value):
    """Whether a value can be placed on a logarithmic axis."""
    return value is not None and math.isfinite(value) and value > 0


def to_float(text):
    """A CSV field as float; None when empty or not a number."""
    try:
        return float(text) if text.strip() else None
    except ValueError:
        return None


def split_argument(argument):
    """Split 'path=LABEL' into (path, label); label None when absent."""
    if os.path.exists(argument) or "=" not in argument:
        return argument, None
    path, _, label = argument.rpartition("=")
    return path, label


def default_label(path):
    """The name of the directory containing the file."""
    directory = os.path.dirname(os.path.abspath(path))
    return os.path.basename(directory) or path


def read_series(argument, selection=None):
    """Read one 'report.csv[=LABEL]' argument into a Series; @p selection
    is the list of --columns (checked by check_columns), None for the
    default quantities."""
    path, label = split_argument(argument)
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            lines = [row for row in csv.reader(stream) if any(row)]
    except OSError as error:
        raise PlotError(f"cannot read {path}: {error.strerror}") from error
    except (csv.Error, UnicodeDecodeError) as error:
        raise PlotError(f"{path}: not a valid CSV file: {error}") from error
    header = [name.strip() for name in lines[0]] if lines else []
    if DOFS not in header or len(lines) < 2:
        raise PlotError(f"{path}: no data rows with a '{DOFS}' column")
    columns = {name: [to_float(row[index]) if index < len(row) else None
                      for row in lines[1:]]
               for index, name in enumerate(header)}
    series = Series(path, label or default_label(path), columns)
    if selection is None and not series.quantities():
        raise PlotError(f"{path}: no usable rows (no positive dofs together "
                        "with a positive error or estimator value)")
    return series


def parse_columns(text):
    """The --columns value as a list of names, without repetitions."""
    names = []
    for name in (part.strip() for part in text.split(",")):
        if name and name not in names:
            names.append(name)
    if not names:
        raise PlotError("--columns: no column named")
    for name in names:
        if name in (DOFS, TIME):
            raise PlotError(f"--columns: '{name}' is an axis, not a "
                            "quantity")
    return names


def check_columns(series_list, selection):
    """Every selected column must be drawable in at least one report, and
    every report must have at least one selected column to draw."""
    for name in selection:
        if any(series.points(DOFS, name) for series in series_list):
            continue
        if not any(name in series.columns for series in series_list):
            available = sorted({column for series in series_list
                                for column in series.columns})
            raise PlotError(f"--columns: no report has a column '{name}' "
                            f"(columns: {','.join(available)})")
        raise PlotError(f"--columns: column '{name}' has no positive value "
                        "in any report")
    for series in series_list:
        if not series.quantities(selection):
            raise PlotError(f"{series.path}: none of the columns "
                            f"{','.join(selection)} has a positive value "
                            "together with positive dofs")


def disambiguate_labels(series_list):
    """Replace repeated labels by the file paths, so the legend is clear."""
    labels = [series.label for series in series_list]
    for series in series_list:
        if labels.count(series.label) > 1:
            series.label = series.path


def quantity_order(series_list, selection=None):
    """All quantities over all files, err_* columns first, then estimator;
    the --columns @p selection as given, if any."""
    if selection is not None:
        return list(selection)
    found = []
    for series in series_list:
        found += [name for name in series.quantities() if name not in found]
    return sorted(found, key=lambda name: (name == ESTIMATOR,
                                           found.index(name)))


def coincide(series_list, first, second):
    """Whether two columns hold the same values in every report."""
    for series in series_list:
        a, b = series.columns.get(first), series.columns.get(second)
        if a is None or b is None or len(a) != len(b):
            return False
        for x, y in zip(a, b):
            if (x is None) != (y is None):
                return False
            if x is not None and abs(x - y) > COINCIDENCE * max(abs(x),
                                                                 abs(y)):
                return False
    return True


def merge_coinciding(series_list, quantities):
    """The quantities to draw, each with its legend label: a quantity that
    coincides with an earlier one is not drawn again, and joins its label."""
    labels = {}
    for name in quantities:
        twin = next((kept for kept in labels
                     if coincide(series_list, kept, name)), None)
        if twin is None:
            labels[name] = name
        else:
            labels[twin] += " = " + name
    return labels


def plot_panel(axes, series_list, colours, x_name, x_label):
    """Draw every quantity of every file against one x column."""
    for index, series in enumerate(series_list):
        marker = MARKERS[index % len(MARKERS)]
        style = LINE_STYLES[index % len(LINE_STYLES)]
        for name, colour in colours.items():
            points = series.points(x_name, name)
            if points:
                x, y = zip(*points)
                axes.loglog(x, y, color=colour, marker=marker,
                            linestyle=style, markersize=5)
    axes.set_xlabel(x_label)
    axes.set_ylabel("error")
    axes.grid(True, which="both", alpha=0.3)


def add_reference_slopes(axes, series_list, quantities):
    """Dashed lines N^{-1/2} and N^{-1}, starting below the data."""
    points = [point for series in series_list for name in quantities
              for point in series.points(DOFS, name)]
    if not points:
        return []
    n_min = min(x for x, _ in points)
    n_max = max(x for x, _ in points)
    if n_max <= n_min:
        return []
    y_start = 0.5 * min(y for x, y in points if x == n_min)
    handles = []
    for exponent, label, dashes in REFERENCE_SLOPES:
        y_end = y_start * (n_max / n_min) ** exponent
        (line,) = axes.loglog([n_min, n_max], [y_start, y_end], color="black",
                              linestyle=dashes, linewidth=1, label=label)
        handles.append(line)
    return handles


def legend_handles(series_list, colours, labels):
    """Proxy artists: one per quantity (colour), one per file (style)."""
    from matplotlib.lines import Line2D

    quantity_handles = [Line2D([], [], color=colour, label=labels[name])
                        for name, colour in colours.items()]
    file_handles = [Line2D([], [], color="grey",
                           marker=MARKERS[index % len(MARKERS)],
                           linestyle=LINE_STYLES[index % len(LINE_STYLES)],
                           label=series.label)
                    for index, series in enumerate(series_list)]
    return quantity_handles, file_handles


def make_figure(series_list, title, selection=None):
    """Build the two-panel figure."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    labels = merge_coinciding(series_list,
                              quantity_order(series_list, selection))
    quantities = list(labels)
    palette = pyplot.rcParams["axes.prop_cycle"].by_key()["color"]
    colours = {name: palette[index % len(palette)]
               for index, name in enumerate(quantities)}

    figure, (left, right) = pyplot.subplots(1, 2, figsize=(13, 5.5))
    plot_panel(left, series_list, colours, DOFS, "degrees of freedom N")
    plot_panel(right, series_list, colours, TIME,
               "cumulative wall time of the method [s] (without error norms)")
    slopes = add_reference_slopes(left, series_list, quantities)

    quantity_handles, file_handles = legend_handles(series_list, colours,
                                                    labels)
    handles = quantity_handles + slopes + file_handles
    columns = min(4, len(handles))
    rows = -(-len(handles) // columns)
    figure.legend(handles=handles, fontsize="small", ncol=columns,
                  loc="lower center", frameon=False)
    if title:
        figure.suptitle(title)
    # Room below the panels for the legend, a line of text per row.
    figure.tight_layout(rect=(0, 0.045 * rows + 0.02, 1, 1))
    return figure


def output_prefix(requested, first_path):
    """PREFIX from --output (a trailing .png/.svg is dropped) or default."""
    if requested is None:
        directory = os.path.dirname(os.path.abspath(first_path))
        return os.path.join(directory, "convergence")
    root, extension = os.path.splitext(requested)
    return root if extension.lower() in (".png", ".svg") else requested


def parse_arguments(argv):
    """Parse the command line."""
    parser = argparse.ArgumentParser(prog=PROG,
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("reports", nargs="+", metavar="report.csv[=LABEL]",
                        help="report file, optionally with a legend label")
    parser.add_argument("--output", metavar="PREFIX",
                        help="write PREFIX.png (default: convergence.png "
                             "beside the first report)")
    parser.add_argument("--title", metavar="T", help="figure title")
    parser.add_argument("--svg", action="store_true",
                        help="also write PREFIX.svg")
    parser.add_argument("--columns", metavar="C1,C2,...",
                        help="comma-separated report columns to plot, in "
                             "this order (default: every err_* column with "
                             "values, then estimator)")
    return parser.parse_args(argv)


def main(argv=None):
    """Entry point; returns the exit status."""
    arguments = parse_arguments(argv)
    try:
        selection = (parse_columns(arguments.columns)
                     if arguments.columns is not None else None)
        series_list = [read_series(argument, selection)
                       for argument in arguments.reports]
        if selection is not None:
            check_columns(series_list, selection)
    except PlotError as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 1
    disambiguate_labels(series_list)
    prefix = output_prefix(arguments.output, series_list[0].path)

    try:
        figure = make_figure(series_list, arguments.title, selection)
    except ImportError as error:
        print(f"{PROG}: error: matplotlib is required ({error}); on Debian "
              "install python3-matplotlib and run with /usr/bin/python3",
              file=sys.stderr)
        return 1
    extensions = ["png", "svg"] if arguments.svg else ["png"]
    for extension in extensions:
        path = f"{prefix}.{extension}"
        try:
            figure.savefig(path, dpi=150)
        except OSError as error:
            print(f"{PROG}: error: cannot write {path}: {error.strerror}",
                  file=sys.stderr)
            return 1
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
