"""settle.outside_patches (a stage of prepare_mesh): crossings that involve a repair patch's faces are taken out,
everything else kept."""

import numpy as np

from inertia_tool.mesh.intersect import SurfaceContacts
from inertia_tool.mesh.settle import outside_patches


def test_patch_crossings_are_dropped_and_the_rest_kept():
    # faces 0, 1 use only vertices read from the file (< 4); faces 2, 3 use a patch apex (vertex 4)
    faces = np.array([[0, 1, 2], [1, 2, 3], [0, 1, 4], [2, 3, 4]])
    contacts = SurfaceContacts(crossing=np.array([[0, 1], [0, 2], [1, 3]]), coplanar_opposite=np.array([[0, 3]]),
                               contact=np.array([[1, 2]]), complete=False, candidate_pairs=7, tested_pairs=6)
    kept, notes = outside_patches(contacts, faces, n_read=4)
    assert isinstance(kept, SurfaceContacts)
    np.testing.assert_array_equal(kept.crossing, [[0, 1]])
    np.testing.assert_array_equal(kept.coplanar_opposite, [[0, 3]])
    np.testing.assert_array_equal(kept.contact, [[1, 2]])
    assert kept.complete is False and kept.candidate_pairs == 7 and kept.tested_pairs == 6
    assert len(notes) == 1 and notes[0].startswith("2 face pairs where a patch crosses")


def test_no_patch_crossing_returns_the_contacts_unchanged():
    faces = np.array([[0, 1, 2], [1, 2, 3], [0, 1, 4]])
    contacts = SurfaceContacts(crossing=np.array([[0, 1]]), coplanar_opposite=np.zeros((0, 2), dtype=np.intp),
                               contact=np.zeros((0, 2), dtype=np.intp), complete=True)
    kept, notes = outside_patches(contacts, faces, n_read=4)
    assert kept is contacts and notes == ()
