"""A folder of another run is refused saying what changed (the tester's D5): the header's
options and the scene's keys with their two values; a folder written before the headers
recorded the scene's keys is still resumed (they are not compared)."""

import pytest
from mpi4py import MPI

from rawehelix.studies.store import orbits_store, writers


def _header(ei, tension_step=0.05, keys=True):
    h = {"scene": "mobile_end", "fingerprint": f"fp{ei}", "windows": [[15.0, 6.0]],
         "tension_step": tension_step}
    if keys:
        h[writers.SCENE_KEYS] = {"helix.EI_Nm2": float(ei), "helix.mass_kg": 1.0}
    return h


def test_a_branch_folder_of_another_run_names_the_change(tmp_path):
    orbits_store.open_directory(tmp_path, _header(4381), MPI.COMM_SELF)
    with pytest.raises(orbits_store.OrbitsStoreError) as err:
        orbits_store.open_directory(tmp_path, _header(6000, 0.1), MPI.COMM_SELF)
    text = str(err.value)
    assert "changed: the scene's keys (--set" in text and "--tension-step" in text
    assert "helix.EI_Nm2 4381.0 -> 6000.0" in text and "helix.mass_kg" not in text


def test_a_folder_without_the_scene_keys_resumes_and_names_options_only(tmp_path):
    orbits_store.open_directory(tmp_path, _header(4381, keys=False), MPI.COMM_SELF)
    orbits_store.open_directory(tmp_path, _header(4381), MPI.COMM_SELF)  # the same run
    with pytest.raises(orbits_store.OrbitsStoreError, match=r"changed: the scene's keys \(--set"):
        orbits_store.open_directory(tmp_path, _header(6000), MPI.COMM_SELF)


def test_changed_lists_the_first_keys_and_counts_the_rest():
    a = {writers.SCENE_KEYS: {f"k{i}": i for i in range(7)}}
    b = {writers.SCENE_KEYS: {f"k{i}": i + 1 for i in range(7)}}
    assert writers.changed(a, b, most=4) == ["k0 0 -> 1", "k1 1 -> 2", "k2 2 -> 3",
                                             "k3 3 -> 4", "3 more scene keys"]
