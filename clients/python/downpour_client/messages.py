"""Small helpers that build downpour.v1 messages from plain Python values."""

from downpour.v1 import downpour_pb2 as pb
from google.protobuf import json_format

_PREFIXES = {"View": "VIEW_", "Mode": "MODE_", "WiperMode": "WIPER_",
             "Background": "BACKGROUND_", "DepthEncoding": "DEPTH_", "Output": "OUTPUT_"}
# Enums whose zero is a value of its own (not "unspecified").
_ZERO_NAMED = {"Background"}


def _enum_value(enum_type, value, field):
    """An enum number from a short name ("COCKPIT"), a full name ("VIEW_COCKPIT") or an int.

    Ints pass through unchecked so that callers can send raw values on purpose.
    """
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    if isinstance(value, str):
        prefix = _PREFIXES[enum_type.DESCRIPTOR.name]
        name = value.strip().upper()
        if not name.startswith(prefix):
            name = prefix + name
        number = enum_type.DESCRIPTOR.values_by_name.get(name)
        if number is not None and (number.number != 0 or enum_type.DESCRIPTOR.name in _ZERO_NAMED):
            return number.number
    allowed = ", ".join(enum_name(enum_type, v.number) for v in enum_type.DESCRIPTOR.values
                        if v.number != 0 or enum_type.DESCRIPTOR.name in _ZERO_NAMED)
    raise ValueError(f"{field}: unknown value {value!r}, expected one of {allowed}")


def enum_name(enum_type, value):
    """The short name of an enum number ("COCKPIT"), or the number as text when unknown."""
    descriptor = enum_type.DESCRIPTOR.values_by_number.get(value)
    if descriptor is None:
        return str(value)
    return descriptor.name.removeprefix(_PREFIXES[enum_type.DESCRIPTOR.name])


def view_value(value, field="view"):
    return _enum_value(pb.View, value, field)


def mode_value(value, field="mode"):
    return _enum_value(pb.Mode, value, field)


def wiper_mode_value(value, field="mode"):
    return _enum_value(pb.WiperMode, value, field)


def background_value(value, field="background"):
    return _enum_value(pb.Background, value, field)


def depth_encoding_value(value, field="depth_encoding"):
    return _enum_value(pb.DepthEncoding, value, field)


# Short names of the ground truth a view can ask for (ViewSpec.outputs), beside the enum's own.
_OUTPUT_ALIASES = {"MASK": "WATER_MASK"}


def output_values(value, field="outputs"):
    """Output numbers from "clean,mask,depth" (short or full names, "mask" for WATER_MASK), or from a
    list of names or numbers; None or "" gives none."""
    if not value:
        return []
    names = value.split(",") if isinstance(value, str) else list(value)
    out = []
    for name in names:
        if isinstance(name, str):
            name = _OUTPUT_ALIASES.get(name.strip().upper(), name)
        out.append(_enum_value(pb.Output, name, field))
    return out


def client_image(view, image, depth=None, depth_encoding="PNG16_CM"):
    """A ClientImage: a picture (JPEG or PNG bytes, the view's size) for a view whose background is
    the client's, and optionally its depth (PNG bytes: "PNG16_CM", a 16-bit grey PNG in
    centimetres, or "CARLA_RGB", CARLA's depth camera's encoding)."""
    message = pb.ClientImage(view=view_value(view), image=image)
    if depth is not None:
        message.depth = depth
        message.depth_encoding = depth_encoding_value(depth_encoding)
    return message


def vec3(xyz):
    x, y, z = xyz
    return pb.Vec3(x=x, y=y, z=z)


def rotation(yaw_pitch_roll):
    yaw, pitch, roll = yaw_pitch_roll
    return pb.Rotation(yaw_deg=yaw, pitch_deg=pitch, roll_deg=roll)


def view_spec(view, width, height, quality=0, fov_deg=0.0, camera_position_m=None,
              camera_rotation_deg=None, focus_distance_m=None, aperture_mm=None,
              exposure_s=None, background=None, outputs=None, haze=False):
    """A ViewSpec; camera pose (VIEW_ROAD, or a forward camera for VIEW_COCKPIT) as (x, y, z) and (yaw, pitch, roll).

    The lens: focus_distance_m (metres) and aperture_mm (aperture diameter, 0 = a pinhole); None
    leaves the field unset, the view's own lens. exposure_s: the shutter time that rain streaks
    show (None: 1/60 s). background: "RENDERED" (None: the server's world) or "CLIENT" (the
    client's pictures, sent as Update.client_images). outputs: the ground truth each frame brings
    beside its JPEG (output_values: "clean,mask,depth"). haze: over the client's pictures, the
    server's haze by their depth (a simulator that draws its own fog leaves it off).
    """
    spec = pb.ViewSpec(view=view_value(view), width=width, height=height,
                       jpeg_quality=quality, fov_deg=fov_deg)
    if camera_position_m is not None:
        spec.camera_position_m.CopyFrom(vec3(camera_position_m))
    if camera_rotation_deg is not None:
        spec.camera_rotation.CopyFrom(rotation(camera_rotation_deg))
    if focus_distance_m is not None:
        spec.focus_distance_m = focus_distance_m
    if aperture_mm is not None:
        spec.aperture_mm = aperture_mm
    if exposure_s is not None:
        spec.exposure_s = exposure_s
    if background is not None:
        spec.background = background_value(background)
    spec.outputs.extend(output_values(outputs))
    spec.haze = bool(haze)
    return spec


def to_view_spec(value):
    """A ViewSpec from a ViewSpec, a tuple (view, width, height[, quality]) or a scenario dict."""
    if isinstance(value, pb.ViewSpec):
        return value
    if isinstance(value, dict):
        return view_spec(value["view"], value["width"], value["height"],
                         value.get("jpeg_quality", 0), value.get("fov_deg", 0.0),
                         focus_distance_m=value.get("focus_distance_m"),
                         aperture_mm=value.get("aperture_mm"),
                         exposure_s=value.get("exposure_s"),
                         background=value.get("background"))
    return view_spec(*value)


def message_dict(message):
    """A message as a dict by proto3's JSON mapping: the .proto's field names, fields at their
    default value included."""
    try:
        return json_format.MessageToDict(message, preserving_proto_field_name=True,
                                         including_default_value_fields=True)
    except TypeError:  # protobuf 5.26 renamed the option
        return json_format.MessageToDict(message, preserving_proto_field_name=True,
                                         always_print_fields_with_no_presence=True)
