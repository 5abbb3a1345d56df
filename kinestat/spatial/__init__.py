"""Spatial algebra: rigid transforms, Euler angles, Plücker lines, twists and wrenches, and the
screw axis of a finite displacement (Nadkarni 1977, ch. III), SE(3) exp/log and the pose error
(:mod:`~kinestat.spatial.se3`), and the input validators (:mod:`~kinestat.spatial.validate`)."""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=['displacement', 'euler', 'plucker', 'screws', 'se3', 'transforms', 'validate'],
    submod_attrs={
        'displacement': [
            'ScrewDisplacement', 'frame_from_points', 'frame_from_triple', 'interpolate_screw',
            'pose_from_screw', 'relative_displacement', 'screw_from_displacement',
            'screw_from_points', 'screw_from_poses', 'screws_between',
        ],
        'euler': [
            'EULER_SEQUENCES', 'GIMBAL_TOL', 'check_sequence', 'euler_from_matrix',
            'is_proper_sequence', 'matrix_from_euler',
        ],
        'plucker': [
            'COINCIDENT', 'CommonNormal', 'INTERSECTING', 'LINE_KINDS', 'LinePair', 'PARALLEL',
            'SKEW', 'classify_lines', 'common_normal', 'is_line', 'line_distance',
            'line_from_point_direction', 'line_from_points', 'mutual_moment', 'normalize_line',
            'point_on_line', 'transform_line',
        ],
        'screws': [
            'adjoint', 'pitch', 'power', 'reciprocal_product', 'screw_axis', 'screw_from_axis',
            'screw_magnitude', 'transform_twist', 'transform_wrench', 'twist', 'twist_matrix',
            'wrench',
        ],
        'se3': ['pose_error', 'so3_exp', 'so3_log', 'twist_exp'],
        'validate': ['as_array', 'as_pose', 'as_unit_vector', 'as_vector3', 'batch_index'],
        'transforms': [
            'apply', 'apply_vector', 'compose', 'inv', 'is_rotation', 'make_pose', 'rot_x', 'rot_y',
            'rot_z', 'rotation', 'skew', 'trans', 'trans_x', 'trans_z', 'translation',
        ],
    },
)
