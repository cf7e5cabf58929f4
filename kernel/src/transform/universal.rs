//! The universal 15-factor chain of seed 003 (S003-3).

use super::{Chain, FactorKind::*};

/// The universal chain's parameters in the seed's order: these are the axis
/// names of [`Chain::universal`], and the order its axis values are given in.
pub const UNIVERSAL_PARAMETERS: [&str; 15] = [
    "a", "b", "c", "phi", "a1", "b1", "c1", "theta", "a2", "b2", "c2", "psi", "a3", "b3", "c3",
];

impl Chain {
    /// The universal chain of docs/math.md §1 (S003-3), every parameter an axis:
    ///
    /// `A = Tx(a3) Ty(b3) Tz(c3) Rx(psi) Tx(a2) Ty(b2) Tz(c2) Ry(theta)
    ///      Tx(a1) Ty(b1) Tz(c1) Rz(phi) Tx(a) Ty(b) Tz(c)`
    ///
    /// Axis values are given in the order of [`UNIVERSAL_PARAMETERS`]
    /// (`a, b, c, phi, a1, ...`); any machine whose motions are a subset is
    /// this chain with the unused values at 0.
    ///
    /// ```
    /// use pilgrim_kernel::{Chain, Point3};
    /// let a = Chain::universal();
    /// let mut q = [0.0; 15];
    /// q[0] = 5.0; // a: the tool moves 5 mm along X
    /// let p = a.apply(&q, &Point3::origin()).unwrap();
    /// assert_eq!(p, Point3::new(5.0, 0.0, 0.0));
    /// ```
    pub fn universal() -> Chain {
        let mut b = Chain::builder();
        for name in UNIVERSAL_PARAMETERS {
            b = b.declare(name);
        }
        b.axis(Tx, "a3")
            .axis(Ty, "b3")
            .axis(Tz, "c3")
            .axis(Rx, "psi")
            .axis(Tx, "a2")
            .axis(Ty, "b2")
            .axis(Tz, "c2")
            .axis(Ry, "theta")
            .axis(Tx, "a1")
            .axis(Ty, "b1")
            .axis(Tz, "c1")
            .axis(Rz, "phi")
            .axis(Tx, "a")
            .axis(Ty, "b")
            .axis(Tz, "c")
            .build()
            .expect("the universal chain is well formed")
    }
}
