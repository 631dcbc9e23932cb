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


def tri6_areas(X, conn):
    """Areas of quadratic triangles (corners, then the mid-edge nodes of 01 12 20), by the 6-point
    rule of Strang and Fix (degree 4; exact for flat triangles)."""
    quad = []
    for a, w in ((0.445948490915965, 0.223381589678011), (0.091576213509771, 0.109951743655322)):
        quad += [(a, a, w), (1 - 2 * a, a, w), (a, 1 - 2 * a, w)]
    area = np.zeros(len(conn))
    P = X[conn]
    for xi, eta, w in quad:
        L = 1 - xi - eta
        dxi = np.array([-(4 * L - 1), 4 * xi - 1, 0.0, 4 * (L - xi), 4 * eta, -4 * eta])
        deta = np.array([-(4 * L - 1), 0.0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (L - eta)])
        g1, g2 = np.einsum("a,eai->ei", dxi, P), np.einsum("a,eai->ei", deta, P)
        area += 0.5 * w * np.linalg.norm(np.cross(g1, g2), axis=1)
    return area
