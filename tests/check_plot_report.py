#!/usr/bin/env python3
"""The figure of source/plot_report.py on a report with two coinciding
columns::

    check_plot_report.py SOURCE_DIR WORKDIR

Writes a report.csv of three rows in which err_lambda_L2 and
err_lambda_L2_omega_h are equal and err_energy differs from both by 1e-6
relative, and checks: the two equal columns are drawn once, under the
label ``err_lambda_L2 = err_lambda_L2_omega_h``; err_energy, which does not
coincide, keeps its own curve; the reference slopes are labelled in N; and
the script writes the PNG (if matplotlib is installed).
"""
import importlib.util
import os
import subprocess
import sys

from checks import check, failures

source, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
report = os.path.join(work, "report.csv")
with open(report, "w") as out:
    out.write("cycle,dofs,cumulative_wall_time_s,err_lambda_L2,"
              "err_lambda_L2_omega_h,err_energy\n")
    for k, (n, e) in enumerate([(100, 0.5), (400, 0.25), (1600, 0.125)]):
        out.write("%d,%d,%g,%r,%r,%r\n" % (k, n, 0.1 * (k + 1), e, e,
                                           e * (1 + 1e-6)))

spec = importlib.util.spec_from_file_location(
    "plot_report", os.path.join(source, "source", "plot_report.py"))
plot_report = importlib.util.module_from_spec(spec)
spec.loader.exec_module(plot_report)
series = [plot_report.read_series(report)]
labels = plot_report.merge_coinciding(
    series, plot_report.quantity_order(series))
check(labels.get("err_lambda_L2") ==
      "err_lambda_L2 = err_lambda_L2_omega_h",
      "coinciding columns drawn once, named together: %s" % labels)
check("err_lambda_L2_omega_h" not in labels,
      "the second of the coinciding columns has no curve of its own")
check(labels.get("err_energy") == "err_energy",
      "a column 1e-6 apart keeps its own curve")
check([label for _, label, _ in plot_report.REFERENCE_SLOPES] ==
      [r"$N^{-1/2}$", r"$N^{-1}$"], "reference slopes labelled in N")
try:
    import matplotlib  # noqa: F401
    result = subprocess.run(
        [sys.executable, os.path.join(source, "source", "plot_report.py"),
         report, "--output", os.path.join(work, "figure")],
        stdout=subprocess.PIPE, text=True)
    check(result.returncode == 0 and
          os.path.exists(os.path.join(work, "figure.png")),
          "the figure is written")
except ImportError:
    print("SKIP the figure itself: no matplotlib")
sys.exit(1 if failures else 0)
