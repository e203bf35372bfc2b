#!/usr/bin/env python3
"""Regenerates Data/mni152_t1_99x117x95_uint8.raw from the MNI ICBM152 2009a T1 template that the
nilearn wheel on PyPI bundles (nilearn/datasets/data/mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz).
Downsampled 2x (2 mm voxels, 2x2x2 mean) to keep the repository small. Needs: pip install nibabel numpy
and the nilearn wheel unpacked (pip download --no-deps nilearn; unzip)."""
import sys
import nibabel as nib
import numpy as np

src = sys.argv[1] if len(sys.argv) > 1 else "nilearn/datasets/data/mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz"
a = np.asarray(nib.load(src).dataobj, dtype=np.float64)
# Pad to even dims and average 2x2x2 blocks.
pad = [(0, s % 2) for s in a.shape]
a = np.pad(a, pad, mode="edge")
a = a.reshape(a.shape[0] // 2, 2, a.shape[1] // 2, 2, a.shape[2] // 2, 2).mean(axis=(1, 3, 5))
a = np.clip(np.rint(a), 0, 255).astype(np.uint8)
nx, ny, nz = a.shape
out = f"mni152_t1_{nx}x{ny}x{nz}_uint8.raw"
# Raw layout: x fastest (Fortran order of the NIfTI i,j,k array).
a.ravel(order="F").tofile(out)
print(out, a.shape, a.min(), a.max())
