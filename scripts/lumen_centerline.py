#!/usr/bin/python3
"""The lumen centerline CSV of a segmented lumen surface, for the patient pipeline
(`patient.centerline`): x, y, z, r in mm at a uniform arc-length spacing, r the equivalent radius
sqrt(A/pi) of the cross-section's area A (scripts/patient/lumen_centerline.py: level sets of a
harmonic field between the two cut ends).

  scripts/lumen_centerline.py SURFACE -o CENTERLINE.csv [--units mm|m|cm] [--spacing 0.2]

SURFACE: a triangulated lumen surface open at both ends (STL, OBJ, PLY, VTK, VTU: what meshio
reads), one vessel without side branches. A surface in metres is refused unless --units m converts
it. Bad input: one line naming the file and what was expected, exit 2. Units: mm.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from patient.centerline_csv import arc_length, write_centerline_csv  # noqa: E402
from patient.errors import PatientInputError  # noqa: E402
from patient.lumen_centerline import lumen_centerline  # noqa: E402
from patient.lumen_surface import UNITS, read_lumen_surface  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("surface")
    ap.add_argument("-o", "--output", required=True, help="centerline CSV to write (x, y, z, r; mm)")
    ap.add_argument("--units", choices=list(UNITS), default="mm", help="length unit of the surface file")
    ap.add_argument("--spacing", type=float, default=0.2, help="station spacing along the centerline (mm)")
    a = ap.parse_args()
    if not 0.01 <= a.spacing <= 5.0:
        print(f"lumen_centerline: error: --spacing: expected 0.01 to 5 mm, got {a.spacing}", file=sys.stderr)
        return 2
    try:
        surface = read_lumen_surface(a.surface, a.units)
        points, radius = lumen_centerline(surface, spacing=a.spacing)
    except PatientInputError as e:
        print(f"lumen_centerline: error: {e}", file=sys.stderr)
        return 2
    write_centerline_csv(
        a.output,
        points,
        radius,
        comment=f"lumen centerline of {os.path.basename(a.surface)} (scripts/lumen_centerline.py)",
    )
    length = float(arc_length(points)[-1])
    print(
        f"lumen_centerline: {a.output}: {len(points)} stations over {length:.2f} mm, "
        f"lumen radius {radius.min():.3f} to {radius.max():.3f} mm"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
