//! The scene of the animation, defined once: the body drawn as a box centred on the reference
//! point, its edges and its nose face, and the turn of NED poses into east-north-up for drawing.
//! The GIF is drawn from these; the HTML page and Python's `imukit.plot.animate` receive them as
//! data ([`box_corners_m`], [`BOX_EDGES`], [`BOX_NOSE`], [`pose_enu`], [`point_enu`]).
use imu_core::{Body, Enu, Ned, Rotation, Vec3};

/// The box's corners in the body frame, m: half the length, width and height along body x, y, z
/// from the reference point. Bit 0 of the index is +x (the nose), bit 1 +y, bit 2 +z.
#[must_use]
pub fn box_corners_m(body_m: [f64; 3]) -> [[f64; 3]; 8] {
    let [l, w, h] = body_m.map(|d| d / 2.0);
    core::array::from_fn(|i| {
        [
            if i & 1 == 0 { -l } else { l },
            if i & 2 == 0 { -w } else { w },
            if i & 4 == 0 { -h } else { h },
        ]
    })
}

/// The twelve edges of the box, as pairs of corner indices of [`box_corners_m`].
pub const BOX_EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// The nose face (body +x), corner indices in drawing order.
pub const BOX_NOSE: [usize; 4] = [1, 3, 7, 5];

/// A navigation-frame point in east-north-up, m: NED `[n, e, d]` becomes `[e, n, −d]` (exactly:
/// the axes are swapped, not rotated in floating point); ENU stays.
#[must_use]
pub fn point_enu(position_m: [f64; 3], ned: bool) -> [f64; 3] {
    let [x, y, z] = position_m;
    if ned { [y, x, -z] } else { position_m }
}

/// A pose to draw: position in east-north-up, m, and the quaternion `[w, x, y, z]` that carries
/// body-frame points into east-north-up.
///
/// `ned = false`: the data is ENU and is returned as it is. `ned = true`: the position is turned
/// into ENU and the attitude becomes `C_enu,b = C_enu,ned · C_ned,b` — the body axes stay those
/// of the data (FRD), only the drawing frame changes. `None` for a zero quaternion.
#[must_use]
pub fn pose_enu(position_m: [f64; 3], q_nb: [f64; 4], ned: bool) -> Option<([f64; 3], [f64; 4])> {
    let r = Rotation::<Body, Ned>::from_wxyz(q_nb)?;
    if ned {
        let to_enu = Rotation::<Ned, Enu>::ned_to_enu();
        Some((point_enu(position_m, true), r.then(&to_enu).to_wxyz()))
    } else {
        Some((position_m, r.to_wxyz()))
    }
}

/// A body-frame point `c_b` of a pose ([`pose_enu`]) in east-north-up, m.
#[must_use]
pub fn body_point_enu(position_m: [f64; 3], q: [f64; 4], c_b: [f64; 3]) -> [f64; 3] {
    let v = Rotation::<Body, Enu>::from_wxyz(q)
        .map_or(c_b, |r| r.apply(Vec3::from_array(c_b)).to_array());
    [
        position_m[0] + v[0],
        position_m[1] + v[1],
        position_m[2] + v[2],
    ]
}
