//! Tools: grinding wheels and cutters, each parameter defined once.

use crate::input::InputError;
use crate::math::{positive, Point3, Real, Vec3};
use crate::transform::ToolFrame;
use serde::{Deserialize, Serialize};

/// A grinding wheel: a disk of `diameter` and `width` whose periphery is
/// rounded with `rounding_radius` (a torus, MATH §2.2). Every other radius
/// is derived ([`Wheel::centre_radius`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Wheel {
    /// Outer diameter (mm).
    pub diameter: Real,
    /// Radius of the peripheral rounding, R_s (mm).
    pub rounding_radius: Real,
    /// Width (mm).
    pub width: Real,
}

impl Wheel {
    /// A wheel from its dimensions.
    ///
    /// # Failures
    /// A dimension that is not positive and finite; a rounding radius above
    /// half the width or half the diameter.
    pub fn new(diameter: Real, rounding_radius: Real, width: Real) -> Result<Self, InputError> {
        positive("wheel diameter", diameter)?;
        positive("wheel rounding radius", rounding_radius)?;
        positive("wheel width", width)?;
        if rounding_radius > 0.5 * width {
            return Err(InputError::out_of_range(
                "wheel rounding radius",
                rounding_radius,
                format!("at most half the width ({})", 0.5 * width),
            ));
        }
        if rounding_radius > 0.5 * diameter {
            return Err(InputError::out_of_range(
                "wheel rounding radius",
                rounding_radius,
                format!("at most half the diameter ({})", 0.5 * diameter),
            ));
        }
        Ok(Self {
            diameter,
            rounding_radius,
            width,
        })
    }

    /// Distance of the rounding's centre circle from the wheel's axis.
    pub fn centre_radius(&self) -> Real {
        0.5 * self.diameter - self.rounding_radius
    }
}

/// The shape of a tool.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ToolShape {
    /// A grinding wheel.
    Wheel(Wheel),
    /// A cylindrical end mill.
    EndMill {
        /// Diameter (mm).
        diameter: Real,
        /// Flute length (mm).
        length: Real,
    },
    /// A turning or threading insert.
    Insert {
        /// Nose radius (mm).
        nose_radius: Real,
    },
}

/// A tool: its shape, the number the control calls it by, and the
/// reference frame the toolpath tracks (a point and an axis in the tool's
/// own frame, whose origin is the machine's programmed point).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tool {
    /// A name for people.
    pub name: String,
    /// The control's tool number (T word).
    pub number: u32,
    /// The shape.
    pub shape: ToolShape,
    /// The tracked point and axis in the tool's frame.
    pub reference: ToolFrame,
}

impl Tool {
    /// A wheel whose programmed point is the lowest point of its rounding
    /// (as the seed programs it) and whose tracked point is the rounding's
    /// centre, R_s above it; the wheel's axis along +Z.
    pub fn wheel(name: &str, number: u32, wheel: Wheel) -> Self {
        Self {
            name: name.to_owned(),
            number,
            shape: ToolShape::Wheel(wheel),
            reference: ToolFrame {
                point: Point3::new(wheel.rounding_radius, 0.0, 0.0),
                axis: Vec3::z(),
            },
        }
    }

    /// An end mill tracked at its tip centre, axis +Z.
    ///
    /// # Failures
    /// A dimension that is not positive and finite.
    pub fn end_mill(
        name: &str,
        number: u32,
        diameter: Real,
        length: Real,
    ) -> Result<Self, InputError> {
        positive("end mill diameter", diameter)?;
        positive("end mill length", length)?;
        Ok(Self {
            name: name.to_owned(),
            number,
            shape: ToolShape::EndMill { diameter, length },
            reference: ToolFrame::default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wheel_limits() {
        let w = Wheel::new(500.0, 20.0, 50.0).unwrap();
        assert_eq!(w.centre_radius(), 230.0);
        let e = Wheel::new(500.0, 30.0, 50.0).unwrap_err().to_string();
        assert!(
            e.contains("wheel rounding radius = 30") && e.contains("half the width"),
            "{e}"
        );
        assert!(Wheel::new(0.0, 1.0, 5.0).is_err());
        assert!(Wheel::new(10.0, -1.0, 5.0).is_err());
        let t = Tool::wheel("w", 1, w);
        assert_eq!(t.reference.point.x, 20.0);
    }
}
