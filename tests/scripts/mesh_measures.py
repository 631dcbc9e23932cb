"""Measures of meshes shared by the script tests."""
import numpy as np


def tet10_volumes(X, conn):
    """Volumes of tet10 in meshio's (VTK) node order, 4-point rule (exact for straight-sided ones)."""
    a, b = 0.5854101966249685, 0.1381966011250105
    dL = np.array([[-1, -1, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    vol = np.zeros(len(conn))
    for q in ((b, b, b), (a, b, b), (b, a, b), (b, b, a)):
        L = [1 - sum(q), *q]
        dN = np.zeros((10, 3))
        for i in range(4):
            dN[i] = (4 * L[i] - 1) * dL[i]
        for k, (i, j) in enumerate(((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))):
            dN[4 + k] = 4 * (L[i] * dL[j] + L[j] * dL[i])
        vol += np.linalg.det(np.einsum("eai,aj->eij", X[conn], dN)) / 24.0
    return vol
