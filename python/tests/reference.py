"""Slow, obvious numpy references the module's answers are compared with."""

import numpy as np


def key_of(voxels: np.ndarray, depth: int) -> np.ndarray:
    """VOLA key per voxel: one 6-bit digit per level, level 0 most significant."""
    v = np.asarray(voxels, dtype=np.uint64)
    key = np.zeros(len(v), dtype=np.uint64)
    for level in range(depth):
        shift = np.uint64(2 * (depth - 1 - level))
        three = np.uint64(3)
        digit = ((v[:, 0] >> shift) & three) + np.uint64(4) * ((v[:, 1] >> shift) & three) + np.uint64(16) * ((v[:, 2] >> shift) & three)
        key = (key << np.uint64(6)) | digit
    return key


def sorted_unique_voxels(voxels: np.ndarray, depth: int) -> np.ndarray:
    """Distinct voxels in key order (the order a tree stores them)."""
    v = np.unique(np.asarray(voxels, dtype=np.int64), axis=0)
    return v[np.argsort(key_of(v, depth), kind="stable")]


def grid_voxels(points: np.ndarray, origin, voxel_size: float) -> np.ndarray:
    return np.floor((points - np.asarray(origin)) / voxel_size).astype(np.int64)


def dense(voxels: np.ndarray, side: int) -> np.ndarray:
    grid = np.zeros((side, side, side), dtype=bool)
    v = np.asarray(voxels, dtype=np.int64)
    grid[v[:, 0], v[:, 1], v[:, 2]] = True
    return grid


def coarsen(grid: np.ndarray) -> np.ndarray:
    """A cell of the next coarser grid is occupied when any of its 4x4x4 cells is."""
    s = grid.shape[0] // 4
    return grid.reshape(s, 4, s, 4, s, 4).any(axis=(1, 3, 5))
