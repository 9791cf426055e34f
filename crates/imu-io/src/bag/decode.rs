//! A ROS message of a known type as a stamp and a row of its type's columns.
use super::ros::{self, MessageType};

/// Rotates `v` by the unit quaternion `q` (scalar first): `q ⊗ v ⊗ q*`.
pub(super) fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let u = [x, y, z];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = cross(u, v).map(|c| 2.0 * c);
    let ut = cross(u, t);
    [
        v[0] + w * t[0] + ut[0],
        v[1] + w * t[1] + ut[1],
        v[2] + w * t[2] + ut[2],
    ]
}

/// Decodes one message of `kind` into its stamp and row (`None`: a message left out, a fix
/// without a fix).
pub(super) fn decode_row<W: ros::Wire>(
    kind: MessageType,
    data: &[u8],
) -> std::result::Result<Option<(i64, Vec<f64>)>, String> {
    use ros::Stamped;
    Ok(Some(match kind {
        MessageType::Imu => {
            let m: ros::Imu<W::Header> = W::parse(data, 1)?;
            let row = [m.linear_acceleration.array(), m.angular_velocity.array()].concat();
            (m.header.stamp_ns()?, row)
        }
        MessageType::MagneticField => {
            let m: ros::MagneticField<W::Header> = W::parse(data, 1)?;
            (
                m.header.stamp_ns()?,
                m.magnetic_field.array().map(|b| b * 1e6).to_vec(),
            )
        }
        MessageType::NavSatFix => {
            let m: ros::NavSatFix<W::Header> = W::parse(data, 1)?;
            if m.status.status == ros::STATUS_NO_FIX {
                return Ok(None);
            }
            // The covariance's east and north variances' mean per horizontal axis, its up
            // variance vertically; −1: not given.
            let c = m.position_covariance;
            let (h, v) = if m.position_covariance_type == ros::COVARIANCE_TYPE_UNKNOWN {
                (-1.0, -1.0)
            } else {
                (((c[0] + c[4]) / 2.0).sqrt(), c[8].sqrt())
            };
            let row = vec![
                m.latitude.to_radians(),
                m.longitude.to_radians(),
                m.altitude,
                if h > 0.0 { h } else { -1.0 },
                if v > 0.0 { v } else { -1.0 },
            ];
            (m.header.stamp_ns()?, row)
        }
        MessageType::PointStamped => {
            let m: ros::PointStamped<W::Header> = W::parse(data, 1)?;
            (m.header.stamp_ns()?, m.point.array().to_vec())
        }
        MessageType::TwistStamped => {
            let m: ros::TwistStamped<W::Header> = W::parse(data, 1)?;
            (m.header.stamp_ns()?, m.twist.linear.array().to_vec())
        }
        MessageType::Odometry => {
            let m: ros::Odometry<W::Header> = W::parse(data, 2)?;
            let q = m.pose.pose.orientation.wxyz();
            let v = rotate(q, m.twist.twist.linear.array());
            let row = [&m.pose.pose.position.array()[..], &v, &q].concat();
            (m.header.stamp_ns()?, row)
        }
        MessageType::PoseStamped => {
            let m: ros::PoseStamped<W::Header> = W::parse(data, 1)?;
            let row = [&m.pose.position.array()[..], &m.pose.orientation.wxyz()].concat();
            (m.header.stamp_ns()?, row)
        }
    }))
}
