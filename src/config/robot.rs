//! Documentation of the `[robot]` keys for `conduit config --defaults`; the section's type is
//! [`crate::emit::robot::RobotSettings`].

/// Documentation of the `[robot]` keys for `conduit config --defaults`.
pub(super) const KEYS: &[super::defaults::KeyDoc] = &[
    super::defaults::k(
        "robot",
        "dh",
        "Denavit–Hartenberg rows of the arm from the base, [a mm, alpha deg, d mm, theta_offset deg] \
         (standard convention); empty = no arm model.",
    ),
    super::defaults::k(
        "robot",
        "workpiece_frame",
        "The conform program's frame in the robot base frame, [x, y, z, rx, ry, rz] in mm and \
         degrees, rotation Rz(rz)·Ry(ry)·Rx(rx) (KUKA A = rz, B = ry, C = rx): $BASE, wobjdata, \
         and the base-frame poses of URScript.",
    ),
    super::defaults::k(
        "robot",
        "tool_frame",
        "The tool centre point (nozzle tip, z into the work) in the flange frame, [x, y, z, rx, \
         ry, rz] as workpiece_frame: $TOOL, tooldata, set_tcp.",
    ),
    super::defaults::k(
        "robot",
        "max_tilt",
        "Largest tilt of the tool axis from the vertical with --tool-axis normal, degrees \
         (--max-tilt overrides).",
    ),
    super::defaults::k(
        "robot",
        "axis_smoothing",
        "Length of path over which surface normals are averaged into tool axes, mm (0 = none).",
    ),
    super::defaults::k(
        "robot",
        "clearance",
        "Lift along the tool axis before and after every path, mm.",
    ),
    super::defaults::k(
        "robot",
        "travel_speed",
        "Speed of travels, approaches and lifts, mm/s.",
    ),
    super::defaults::k(
        "robot",
        "acceleration",
        "Tool acceleration of URScript moves, mm/s² (written in m/s²).",
    ),
    super::defaults::k(
        "robot",
        "blend",
        "Blend radius between dispensing moves, mm (URScript r, KRL C_DIS, RAPID zone); 0 = exact \
         stop at every point.",
    ),
    super::defaults::k(
        "robot",
        "dispense_output",
        "Digital output of the dispenser: URScript set_digital_out(n, ...), KRL $OUT[n].",
    ),
    super::defaults::k(
        "robot",
        "dispense_signal",
        "Digital output signal of the dispenser in RAPID (SetDO name, 1/0).",
    ),
    super::defaults::k(
        "robot",
        "five_axis",
        "gcode-5axis output: \"ijk\" (G1 X Y Z I J K, tip and tool vector), \"head\" (pivot \
         position and rotary angles) or \"table\" (part turned so the tool is vertical).",
    ),
    super::defaults::k(
        "robot",
        "rotary_axes",
        "Rotary axes of a head or table: \"AC\" (tilt about x, then C about z) or \"BC\" (tilt \
         about y).",
    ),
    super::defaults::k(
        "robot",
        "rotary_signs",
        "Direction of the tilt and C axes: 1 = right-handed about +x/+y and +z, -1 = reversed.",
    ),
    super::defaults::k(
        "robot",
        "pivot_length",
        "Head: distance from the rotary pivot to the tool tip along the tool axis, mm.",
    ),
    super::defaults::k(
        "robot",
        "table_centre",
        "Table: where the rotary axes cross, in the program frame [x, y, z], mm.",
    ),
];
