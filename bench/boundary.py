"""Shared by the splat figure scripts: a mask of boundaries in an image,
pixels within `grow` of a factor-`factor` change of luminance between
neighbours (shadow edges, silhouettes, small objects), where boundary and
proximity bias show."""
import numpy as np


def boundary_mask(lum, eps=1e-2, factor=2.0, grow=2):
    L = np.log(lum + eps * lum.mean())
    edge = np.zeros(L.shape, bool)
    for ax in (0, 1):
        d = np.abs(np.diff(L, axis=ax)) > np.log(factor)
        if ax:
            edge[:, :-1] |= d
            edge[:, 1:] |= d
        else:
            edge[:-1, :] |= d
            edge[1:, :] |= d
    mask = edge
    for _ in range(grow):
        m = mask.copy()
        m[1:, :] |= mask[:-1, :]
        m[:-1, :] |= mask[1:, :]
        m[:, 1:] |= mask[:, :-1]
        m[:, :-1] |= mask[:, 1:]
        mask = m
    return mask
