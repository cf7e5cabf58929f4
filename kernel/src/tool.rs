//! Tools: grinding wheels and cutters, each parameter defined once.

use crate::input::InputError;
use crate::math::{positive, Point3, Real, Vec3};
use crate::transform::ToolFrame;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

mod thread_cutter;

pub use thread_cutter::{GroundFlanks, ThreadCutter, ARC_TOLERANCE, FORM_STEP};

/// A grinding wheel: a disk of `diameter` and `width` whose periphery is
/// rounded with `rounding_radius` (a torus, docs/math.md §2.2). Every other radius
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

    /// The flat of the periphery between the two roundings, in the axial
    /// section: `width - 2 R_s` (0 for a wheel rounded across its width).
    pub fn flat(&self) -> Real {
        (self.width - 2.0 * self.rounding_radius).max(0.0)
    }

    /// The ridge this wheel leaves on a straight generatrix when its touches
    /// are `f` mm apart (the feed per revolution, docs/math.md §2.4): the
    /// rounding's, [`rounding_ridge`]. The flat is not counted: it covers
    /// the gap between touches only on a surface parallel to the wheel's
    /// axis; on a slope `s` it stands off the surface by `s` per mm and the
    /// rounding does the cutting (a mandrel has no such cylinder). The
    /// verification replays the true section, flat included, everywhere.
    pub fn ridge(&self, f: Real) -> Real {
        rounding_ridge(self.rounding_radius, f)
    }

    /// The largest feed per revolution (mm) whose ridge is at most
    /// `height` mm: the inverse of [`Self::ridge`].
    pub fn feed_for_ridge(&self, height: Real) -> Real {
        let r = self.rounding_radius;
        let h = height.clamp(0.0, r);
        2.0 * (r * r - (r - h) * (r - h)).sqrt()
    }

    /// Distance of the rounding's centre circle from the wheel's axis.
    pub fn centre_radius(&self) -> Real {
        0.5 * self.diameter - self.rounding_radius
    }
}

/// The ridge a rounding of radius `r` leaves between touches `f` mm apart
/// on a straight generatrix: `r - sqrt(r^2 - (f/2)^2)`, `f^2 / (8 r)` to
/// first order (`r` once the touches are `2 r` apart or more).
pub fn rounding_ridge(r: Real, f: Real) -> Real {
    let half = (f / 2.0).max(0.0);
    if half >= r {
        return r;
    }
    r - (r * r - half * half).sqrt()
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
    /// A thread cutter: its section in the axial plane.
    ThreadCutter(ThreadCutter),
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
    /// Where a wheel's frame has its origin (how its solid is placed).
    #[serde(default, skip_serializing_if = "WheelOrigin::is_periphery")]
    pub origin: WheelOrigin,
    /// The tool's own sizes of the machine's bodies that ride with it
    /// (its holder's, its boring bar's), by the names of the machine
    /// constants those bodies are sized by: a tool table's row says them,
    /// the run places the bodies with them in place of the machine's
    /// values. Empty: the machine's.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub bodies: BTreeMap<String, Real>,
}

/// Where a wheel's own frame has its origin: the machine's programmed point
/// on the wheel (the tool frame of its chain).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WheelOrigin {
    /// The lowest point of the periphery, the wheel's axis along +Z at
    /// `x = diameter / 2` (the 3K152VF20: the seed programs that point).
    #[default]
    Periphery,
    /// The wheel's centre, its axis along +Z (the caliber grinders).
    Centre,
}

impl WheelOrigin {
    /// Whether this is the default, [`Self::Periphery`].
    pub fn is_periphery(&self) -> bool {
        *self == Self::Periphery
    }
}

impl Tool {
    /// The centre of the tool's spindle in the tool frame: a wheel's centre
    /// (on its axis, in its middle plane), the tool frame's origin for other
    /// tools. The machine's bodies mounted on the tool (a guard, a holder)
    /// are placed from it, so they follow the wheel's size.
    pub fn spindle_centre(&self) -> Vec3 {
        match (self.shape, self.origin) {
            (ToolShape::Wheel(w), WheelOrigin::Periphery) => Vec3::new(w.diameter / 2.0, 0.0, 0.0),
            _ => Vec3::zeros(),
        }
    }

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
            origin: WheelOrigin::Periphery,
            bodies: BTreeMap::new(),
        }
    }

    /// A wheel whose programmed and tracked point is its centre, its axis
    /// along +Z (the caliber grinders' tool frame, docs/math.md §3.5).
    pub fn wheel_at_centre(name: &str, number: u32, wheel: Wheel) -> Self {
        Self {
            name: name.to_owned(),
            number,
            shape: ToolShape::Wheel(wheel),
            reference: ToolFrame::default(),
            origin: WheelOrigin::Centre,
            bodies: BTreeMap::new(),
        }
    }

    /// Whether the tool cuts inside a bore (a thread cutter on a boring
    /// bar): the machine's bodies for such tools hold it.
    pub fn cuts_inside(&self) -> bool {
        matches!(self.shape, ToolShape::ThreadCutter(c) if c.inside)
    }

    /// A thread cutter tracked at its tip's centre (the tool frame's
    /// origin), its section in the tool frame's XZ plane (X radial, Z
    /// along the part's axis).
    pub fn thread_cutter(name: &str, number: u32, cutter: ThreadCutter) -> Self {
        Self {
            name: name.to_owned(),
            number,
            shape: ToolShape::ThreadCutter(cutter),
            reference: ToolFrame::default(),
            origin: WheelOrigin::Periphery,
            bodies: BTreeMap::new(),
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
            origin: WheelOrigin::Periphery,
            bodies: BTreeMap::new(),
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

    #[test]
    fn ridges_and_the_feed_that_holds_them() {
        let w = Wheel::new(500.0, 20.0, 40.0).unwrap();
        assert_eq!(w.flat(), 0.0);
        // The seed's screen: f = 5 mm at R_s = 20: about 157 um.
        assert!((w.ridge(5.0) - 0.15686).abs() < 1e-5, "{}", w.ridge(5.0));
        let f = w.feed_for_ridge(0.0005);
        assert!((w.ridge(f) - 0.0005).abs() < 1e-12);
        // A flat of 10 mm: the rounding's ridge all the same (on a slope
        // the flat stands off and the rounding cuts).
        let flat = Wheel::new(500.0, 15.0, 40.0).unwrap();
        assert_eq!(flat.flat(), 10.0);
        assert!((flat.ridge(10.0) - (15.0 - (225.0f64 - 25.0).sqrt())).abs() < 1e-12);
        assert!(
            (flat.feed_for_ridge(0.0005) - 2.0 * (15.0f64.powi(2) - 14.9995f64.powi(2)).sqrt())
                .abs()
                < 1e-12
        );
    }
}
