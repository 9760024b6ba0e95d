"""A moving polyline as an XDMF time series (HDF5 data), for ParaView.

meshio's TimeSeriesWriter shares one geometry between all steps, so the
helix would not move; here every step has its own Geometry (and the shared
Topology), and the XML is rewritten after each step, so an interrupted run
leaves a readable file.  meshio's TimeSeriesReader reads it (points of the
first step, point data of every step; ``position_m`` holds each step's points).
Rank 0 only.
"""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np

_TYPES = {1: "Scalar", 3: "Vector"}


class PolylineSeries:
    def __init__(self, path: Path):
        self.path = Path(path)
        self.h5_path = self.path.with_suffix(".h5")
        self.h5 = h5py.File(self.h5_path, "w")
        self.grids: list[str] = []
        self.n = None

    def write(self, t: float, points: np.ndarray, point_data: dict):
        """One step: points (n, 3) [m] and point data (n,) or (n, 3)."""
        k = len(self.grids)
        points = np.asarray(points, dtype=float)
        if self.n is None:
            self.n = len(points)
            topo = np.stack([np.arange(self.n - 1), np.arange(1, self.n)], axis=1)
            self.h5.create_dataset("topology", data=topo)
        self.h5.create_dataset(f"step{k}/geometry", data=points)
        attrs = []
        for name, values in {"position_m": points, **point_data}.items():
            values = np.asarray(values, dtype=float)
            self.h5.create_dataset(f"step{k}/{name}", data=values)
            dim = 1 if values.ndim == 1 else values.shape[1]
            dims = f"{self.n}" if dim == 1 else f"{self.n} {dim}"
            attrs.append(
                f'<Attribute Name="{name}" AttributeType="{_TYPES[dim]}" Center="Node">'
                f'<DataItem Dimensions="{dims}" Format="HDF" NumberType="Float" Precision="8">'
                f'{self.h5_path.name}:/step{k}/{name}</DataItem></Attribute>')
        self.h5.flush()
        self.grids.append(
            f'<Grid Name="step{k}" GridType="Uniform"><Time Value="{t:.10g}"/>'
            f'<Topology TopologyType="Polyline" NodesPerElement="2" NumberOfElements="{self.n - 1}">'
            f'<DataItem Dimensions="{self.n - 1} 2" Format="HDF" NumberType="Int" Precision="8">'
            f'{self.h5_path.name}:/topology</DataItem></Topology>'
            f'<Geometry GeometryType="XYZ"><DataItem Dimensions="{self.n} 3" Format="HDF" '
            f'NumberType="Float" Precision="8">{self.h5_path.name}:/step{k}/geometry</DataItem>'
            f'</Geometry>{"".join(attrs)}</Grid>')
        self._write_xml()

    def _write_xml(self):
        xml = ('<?xml version="1.0"?>\n<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">'
               '<Domain><Grid Name="centre_line" GridType="Collection" CollectionType="Temporal">\n'
               + "\n".join(self.grids) + "\n</Grid></Domain></Xdmf>\n")
        tmp = self.path.with_name("." + self.path.name + ".tmp")
        tmp.write_text(xml)
        os.replace(tmp, self.path)

    def close(self):
        self.h5.close()
