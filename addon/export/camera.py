"""Camera converter: Blender's camera and sensor fit onto the renderer's camera.

Blender measures the sensor, shift and orthographic scale along the *fit*
dimension: the larger image side for AUTO, the width for HORIZONTAL, the height
for VERTICAL (``BKE_camera_params_compute_viewplane``). The renderer takes the
full horizontal angle of view and shift and ortho scale relative to the larger
image side, so this module converts.
"""

import math

import numpy as np

from .scene_data import CameraData


def fit_is_horizontal(sensor_fit, width, height):
    """Whether the sensor maps onto the image width (else the height)."""
    if sensor_fit == 'AUTO':
        return width >= height
    return sensor_fit == 'HORIZONTAL'


def horizontal_fov(camera, width, height):
    """Full horizontal angle of view (radians) of a perspective camera."""
    horizontal = fit_is_horizontal(camera.sensor_fit, width, height)
    if camera.sensor_fit == 'VERTICAL':
        sensor = camera.sensor_height
    else:
        sensor = camera.sensor_width
    half_tan = 0.5 * sensor / camera.lens
    if not horizontal:
        half_tan *= width / height
    return 2.0 * math.atan(half_tan)


def convert_camera(camera_object, width, height, warn, frame=None, view=None):
    """CameraData for a camera object (evaluated) at the given image size; frame (a
    RenderFrame) adds non-square pixels and a render region of a larger frame; view is
    (matrix, shift_x) of one multi-view eye, from the RenderEngine's camera_model_matrix
    and camera_shift_x, in place of the object's."""
    camera = camera_object.data
    matrix = np.array(view[0] if view else camera_object.matrix_world, dtype=np.float64)
    shift_x = float(view[1]) if view else float(camera.shift_x)
    to_world = _without_scale(matrix).astype(np.float32)
    if frame is not None:
        # Blender fits the sensor to the frame's shape on screen, pixel aspect included.
        width, height = frame.film_size

    horizontal = fit_is_horizontal(camera.sensor_fit, width, height)
    fit_side = width if horizontal else height
    # Blender's units (fraction of the fit side) -> fraction of the larger side.
    to_larger = fit_side / max(width, height)

    if camera.type == 'PANO':
        warn(f"camera '{camera_object.name}': panoramic cameras are not supported; "
             "rendering as perspective")
    projection = "orthographic" if camera.type == 'ORTHO' else "perspective"
    data = CameraData(
        to_world=np.ascontiguousarray(to_world),
        fov_x=horizontal_fov(camera, width, height),
        shift_x=shift_x * to_larger,
        shift_y=float(camera.shift_y) * to_larger,
        projection=projection,
        ortho_scale=float(camera.ortho_scale) / to_larger)
    if frame is not None:
        data.pixel_aspect = frame.pixel_aspect
        data.region = frame.region
    dof = camera.dof
    if dof.use_dof and projection == "perspective":
        data.aperture_radius, data.focus_distance = _depth_of_field(camera_object, matrix)
    return data


def viewport_camera(region_data, width, height, behind=0.0):
    """CameraData of a 3D view (its RegionView3D) for an image of width x height covering
    the region: the view matrix's inverse, and the angle of view, shift and orthographic
    scale read from the window (projection) matrix, so that a camera view with its zoom and
    offset, lens and region border all come out as Blender draws them. An OpenGL projection
    has P[0][0] = 1 / tan(half angle) and P[0][2] = the window centre's x over its half
    width (perspective); P[0][0] = 1 / half width and P[0][3] = -centre x / half width
    (orthographic). An orthographic view also shows what lies up to `behind` units
    behind its origin (Blender clips it at half the clip end): its rays start there."""
    view = np.array(region_data.view_matrix, dtype=np.float64)
    to_world = _without_scale(np.linalg.inv(view))
    if not region_data.is_perspective:
        to_world[:3, 3] += to_world[:3, 2] * behind
    to_world = to_world.astype(np.float32)
    p = np.array(region_data.window_matrix, dtype=np.float64)
    larger_is_width = width >= height
    if region_data.is_perspective:
        tan_x, tan_y = 1.0 / p[0, 0], 1.0 / p[1, 1]
        tan_larger = tan_x if larger_is_width else tan_y
        return CameraData(to_world=np.ascontiguousarray(to_world),
                          fov_x=2.0 * math.atan(tan_x),
                          shift_x=p[0, 2] * tan_x / (2.0 * tan_larger),
                          shift_y=p[1, 2] * tan_y / (2.0 * tan_larger))
    half_x, half_y = 1.0 / p[0, 0], 1.0 / p[1, 1]
    half_larger = half_x if larger_is_width else half_y
    return CameraData(to_world=np.ascontiguousarray(to_world), fov_x=1.0,
                      projection="orthographic", ortho_scale=2.0 * half_larger,
                      shift_x=-p[0, 3] * half_x / (2.0 * half_larger),
                      shift_y=-p[1, 3] * half_y / (2.0 * half_larger))


def view_camera(scene, camera_object, view):
    """The camera object a multi-view view renders through: with Output > Views set to
    Multi-View, the object named as camera_object with its view suffix swapped for this
    view's ("Cam_L" -> "Cam_R"), as Blender picks it (BKE_camera_multiview_render); the
    camera itself for Stereo 3D, or where no such object exists."""
    render = scene.render
    if not view or not render.use_multiview or render.views_format != 'MULTIVIEW':
        return camera_object
    suffix = render.views[view].camera_suffix if view in render.views else ""
    name, stem_length, best = camera_object.name, None, -1
    for other in render.views:
        ending = other.camera_suffix
        if len(ending) >= best and len(ending) <= len(name) and name.endswith(ending):
            stem_length, best = len(name) - len(ending), len(ending)
    if stem_length is None:
        return camera_object
    candidate = scene.objects.get(name[:stem_length] + suffix)
    return candidate if candidate is not None and candidate.type == 'CAMERA' else camera_object


def _without_scale(matrix):
    """Rotation and translation only: Blender ignores camera object scale for rays."""
    result = matrix.copy()
    for axis in range(3):
        length = np.linalg.norm(result[:3, axis])
        if length > 0.0:
            result[:3, axis] /= length
    return result


def _depth_of_field(camera_object, matrix):
    """Aperture radius in scene units and focus distance, as Cycles computes them:
    radius = focal length / (2 f-stop) with the focal length in metres."""
    camera = camera_object.data
    dof = camera.dof
    radius = 0.0
    if dof.aperture_fstop > 0.0:
        radius = 0.5 * camera.lens * 1e-3 / dof.aperture_fstop
    distance = dof.focus_distance
    if dof.focus_object is not None:
        target = np.array(dof.focus_object.matrix_world, dtype=np.float64)[:3, 3]
        view = -matrix[:3, 2] / max(np.linalg.norm(matrix[:3, 2]), 1e-30)
        distance = abs(float(np.dot(view, target - matrix[:3, 3])))
    return radius, max(float(distance), 1e-6)
