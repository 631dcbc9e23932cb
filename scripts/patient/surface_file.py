"""Reading a surface or polyline file into a meshio.Mesh: VTK XML PolyData (.vtp, what SimVascular
and VMTK write) through VTK's own reader (python3-vtk9), every other format (STL, OBJ, PLY, VTK,
VTU, ...) through meshio. Polygons come back as triangles, polylines as line cells (one cell per
polyline, in their point order), point-data arrays as numpy arrays. Errors are PatientInputError
naming the file. Units as in the file."""
import os

import numpy as np

from .errors import PatientInputError


def read_mesh(path, what):
    """The file at `path` as a meshio.Mesh; `what` says what the file should hold, for messages."""
    import meshio  # only the patient routes that read files need it (python3-meshio)

    if not os.path.isfile(path):
        raise PatientInputError(f"{path}: no such file ({what})")
    if path.lower().endswith(".vtp"):
        return _read_vtp(path, what, meshio)
    try:
        return meshio.read(path)
    except Exception as e:  # meshio raises many types for unreadable files
        raise PatientInputError(f"{path}: cannot read {what} with meshio: {type(e).__name__}: {e}")


def _read_vtp(path, what, meshio):
    try:
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
    except ImportError:
        raise PatientInputError(
            f"{path}: reading .vtp needs VTK's Python module (Debian: apt-get install python3-vtk9; "
            "scripts/setup.sh installs it), or convert the file to STL, VTK or VTU"
        ) from None
    vtk.vtkObject.GlobalWarningDisplayOff()  # a bad file is reported below, not on VTK's own stderr
    errors = []
    reader = vtk.vtkXMLPolyDataReader()
    reader.AddObserver("ErrorEvent", lambda obj, ev: errors.append(ev))
    reader.SetFileName(path)
    reader.Update()
    poly = reader.GetOutput()
    if errors or reader.GetErrorCode() or poly is None or poly.GetNumberOfPoints() == 0:
        raise PatientInputError(f"{path}: cannot read {what}: not a VTK XML PolyData file with points")
    points = vtk_to_numpy(poly.GetPoints().GetData()).astype(float)
    cells = []
    if poly.GetNumberOfPolys() > 0:
        tri = vtk.vtkTriangleFilter()  # polygons of more than three corners split into triangles
        tri.SetInputData(poly)
        tri.PassLinesOff()
        tri.PassVertsOff()
        tri.Update()
        conn = vtk_to_numpy(tri.GetOutput().GetPolys().GetData())
        # the filter keeps the points; its connectivity is [3, a, b, c, 3, ...]
        cells.append(("triangle", conn.reshape(-1, 4)[:, 1:].astype(np.int64)))
    lines = poly.GetLines()
    ids = vtk.vtkIdList()
    lines.InitTraversal()
    while lines.GetNextCell(ids):
        cells.append(("line", np.array([ids.GetId(i) for i in range(ids.GetNumberOfIds())], dtype=np.int64)))
    point_data = {}
    pd = poly.GetPointData()
    for i in range(pd.GetNumberOfArrays()):
        arr = pd.GetArray(i)
        if arr is not None and arr.GetName():
            point_data[arr.GetName()] = vtk_to_numpy(arr).astype(float)
    mesh = meshio.Mesh(points, [(t, d) for t, d in cells if t == "triangle"], point_data=point_data)
    mesh.polylines = [d for t, d in cells if t == "line"]  # one id array per polyline, in order
    return mesh


def write_vtp(path, points, polys=None, lines=None, point_data=None):
    """A VTK XML PolyData file: polygons and polylines as lists of point-id lists, point-data arrays
    by name (the inverse of read_mesh for .vtp; used by the lesion generator and the tests)."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk

    poly = vtk.vtkPolyData()
    p = vtk.vtkPoints()
    p.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=float), deep=True))
    poly.SetPoints(p)
    for cells, setter in ((polys, poly.SetPolys), (lines, poly.SetLines)):
        if cells is not None:
            arr = vtk.vtkCellArray()
            for c in cells:
                arr.InsertNextCell(len(c))
                for i in c:
                    arr.InsertCellPoint(int(i))
            setter(arr)
    for name, values in (point_data or {}).items():
        a = numpy_to_vtk(np.ascontiguousarray(values, dtype=float), deep=True)
        a.SetName(name)
        poly.GetPointData().AddArray(a)
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(str(path))
    w.SetInputData(poly)
    if w.Write() != 1:
        raise OSError(f"{path}: VTK could not write the file")
    return path
