//! A nominal from a DXF drawing: a named layer's chain of LWPOLYLINE
//! (bulges as arcs), LINE, ARC and SPLINE (approximated within a stated
//! chordal tolerance) in the drawing's units, z along the drawing's X, the
//! radius (or the diameter) along its Y, from its origin; the half with
//! Y >= 0 of a full outline. The file is read by the `dxf` crate; only the
//! chaining into a profile is ours.

use super::{Bulge, Profile, ProfileBuilder, ProfileError};
use crate::math::Real;

/// What reading a drawing takes.
#[derive(Debug, Clone, PartialEq)]
pub struct DxfOptions {
    /// The layer holding the outline (its name, case-insensitive).
    pub layer: String,
    /// Whether the drawing's Y is the diameter (else the radius).
    pub diameter: bool,
    /// How far a SPLINE's chords may stray from it, and an arc's nodes'
    /// chords from the arc (mm).
    pub chordal: Real,
}

/// A drawing that cannot be read as a nominal: where and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DxfError {
    /// The file is not a DXF the reader understands.
    #[error("{file}: not a readable DXF drawing: {why}")]
    Unreadable {
        /// The file.
        file: String,
        /// The reader's message.
        why: String,
    },
    /// The header's `$INSUNITS` is not a length pilgrim converts.
    #[error("{file}: the drawing's units ($INSUNITS {code}) are {what}; save it in millimetres, centimetres, metres or inches")]
    Units {
        /// The file.
        file: String,
        /// `$INSUNITS`.
        code: i32,
        /// What they are.
        what: String,
    },
    /// Nothing to read on the layer.
    #[error("{file}: layer '{layer}' holds no LINE, ARC, LWPOLYLINE or SPLINE above the axis (layers with entities: {layers})")]
    EmptyLayer {
        /// The file.
        file: String,
        /// The layer asked for.
        layer: String,
        /// The layers the drawing's entities are on.
        layers: String,
    },
    /// An entity that cannot be part of a profile x(z), or a chain that
    /// does not close.
    #[error("{file}: {what}")]
    Entity {
        /// The file.
        file: String,
        /// The entity (type and handle), where, and why.
        what: String,
    },
    /// The chain built, but not as a profile.
    #[error("{file}: {source}")]
    Profile {
        /// The file.
        file: String,
        /// Why.
        source: ProfileError,
    },
}

/// One piece of the outline in mm, from `a` to `b` (z increasing once
/// oriented): a line, or an arc of `radius` bulging as `bulge`.
#[derive(Debug, Clone)]
struct Piece {
    a: (Real, Real),
    b: (Real, Real),
    arc: Option<(Real, Bulge)>,
    /// `LINE #2A`, for messages.
    name: String,
}

impl Piece {
    fn reversed(mut self) -> Self {
        std::mem::swap(&mut self.a, &mut self.b);
        // An arc's bulge is the same seen from either end.
        self
    }
}

/// The nominal the drawing `bytes` (file `file`) gives on `options.layer`.
///
/// # Failures
/// An unreadable file, units it does not state or pilgrim does not convert,
/// an empty layer, a vertical piece inside the outline, a gap or fork in
/// the chain (naming the entity, its handle and where), an arc the profile
/// cannot follow as x(z).
pub fn profile_from_dxf(
    bytes: &[u8],
    file: &str,
    options: &DxfOptions,
) -> Result<Profile, DxfError> {
    crate::math::positive("DXF chordal tolerance", options.chordal).map_err(|e| {
        DxfError::Profile {
            file: file.into(),
            source: e.into(),
        }
    })?;
    let drawing =
        dxf::Drawing::load(&mut std::io::Cursor::new(bytes)).map_err(|e| DxfError::Unreadable {
            file: file.into(),
            why: crate::files::excerpt(&e.to_string()),
        })?;
    let scale = units(&drawing, file)?;
    let y_scale = if options.diameter { 0.5 } else { 1.0 };
    let point = |x: Real, y: Real| (x * scale, y * scale * y_scale);
    let mut pieces = Vec::new();
    let mut layers: Vec<String> = Vec::new();
    for e in drawing.entities() {
        if !layers.contains(&e.common.layer) {
            layers.push(e.common.layer.clone());
        }
        if !e.common.layer.eq_ignore_ascii_case(&options.layer) {
            continue;
        }
        pieces_of(e, &point, (scale, y_scale), options, file, &mut pieces)?;
    }
    let upper = upper_half(pieces);
    if upper.is_empty() {
        return Err(DxfError::EmptyLayer {
            file: file.into(),
            layer: crate::files::excerpt(&options.layer),
            layers: crate::files::excerpt(&layers.join(", ")),
        });
    }
    let chain = chained(upper, file)?;
    let mut b = ProfileBuilder::start(chain[0].a.0, chain[0].a.1);
    for p in &chain {
        b = match p.arc {
            None => b.line_to(p.b.0, p.b.1),
            Some((r, bulge)) => b.arc_to(p.b.0, p.b.1, r, bulge),
        };
    }
    let span = chain[chain.len() - 1].b.0 - chain[0].a.0;
    // Each stretch named by its entity, as the drawing's author knows it.
    let named = |p: Profile| {
        let sources = (p.sources().iter())
            .map(|s| super::Source {
                label: chain.get(s.index).map_or(s.label.clone(), |c| {
                    format!("{} (from z = {:.4}, x = {:.4} mm)", c.name, c.a.0, c.a.1)
                }),
                ..s.clone()
            })
            .collect();
        p.with_sources(sources)
    };
    b.build(options.chordal, span.max(options.chordal))
        .map(named)
        .map_err(|e| {
            // The builder names segments by index: the chain's own names.
            let text = e.to_string();
            let named = (0..chain.len())
                .rev()
                .find(|i| text.contains(&format!("segment {i}")));
            match named {
                Some(i) => DxfError::Entity {
                    file: file.into(),
                    what: format!(
                        "{} (from z = {:.4}, x = {:.4} mm): {text}",
                        chain[i].name, chain[i].a.0, chain[i].a.1
                    ),
                },
                None => DxfError::Profile {
                    file: file.into(),
                    source: e,
                },
            }
        })
}

/// The pieces (in mm) one entity of the outline's layer gives, appended
/// to `pieces`: a LINE, an ARC, an LWPOLYLINE's segments (bulges as arcs),
/// a SPLINE's chords; other entities give none.
fn pieces_of(
    e: &dxf::entities::Entity,
    point: &dyn Fn(Real, Real) -> (Real, Real),
    (scale, y_scale): (Real, Real),
    options: &DxfOptions,
    file: &str,
    pieces: &mut Vec<Piece>,
) -> Result<(), DxfError> {
    let name = |kind: &str| format!("{kind} #{}", e.common.handle.as_string());
    match &e.specific {
        dxf::entities::EntityType::Line(l) => pieces.push(Piece {
            a: point(l.p1.x, l.p1.y),
            b: point(l.p2.x, l.p2.y),
            arc: None,
            name: name("LINE"),
        }),
        dxf::entities::EntityType::Arc(a) => {
            let at = |deg: Real| {
                let t = deg.to_radians();
                point(
                    a.center.x + a.radius * t.cos(),
                    a.center.y + a.radius * t.sin(),
                )
            };
            let (p, q) = (at(a.start_angle), at(a.end_angle));
            if options.diameter {
                return Err(entity(file, &name("ARC"), p, "an arc on a drawing of diameters is no circle in the section: draw the radius (diameter: false)".into()));
            }
            let sweep = (a.end_angle - a.start_angle).rem_euclid(360.0);
            if sweep >= 180.0 {
                return Err(entity(
                    file,
                    &name("ARC"),
                    p,
                    format!("sweeps {sweep:.3} deg: more than half a turn is not a profile x(z)"),
                ));
            }
            // Counter-clockwise from p to q: seen with z increasing
            // (p left of q) it bulges toward -x.
            let ccw_left_to_right = p.0 < q.0;
            let bulge = if ccw_left_to_right {
                Bulge::In
            } else {
                Bulge::Out
            };
            pieces.push(Piece {
                a: p,
                b: q,
                arc: Some((a.radius * scale, bulge)),
                name: name("ARC"),
            });
        }
        dxf::entities::EntityType::LwPolyline(l) => {
            let v = &l.vertices;
            let closed = l.flags & 1 == 1;
            let n = if closed {
                v.len()
            } else {
                v.len().saturating_sub(1)
            };
            for i in 0..n {
                let (s, t) = (&v[i], &v[(i + 1) % v.len()]);
                let (p, q) = (point(s.x, s.y), point(t.x, t.y));
                let arc = if s.bulge == 0.0 {
                    None
                } else {
                    if options.diameter {
                        return Err(entity(file, &name("LWPOLYLINE"), p, "a bulge on a drawing of diameters is no circle in the section: draw the radius (diameter: false)".into()));
                    }
                    let theta = 4.0 * s.bulge.abs().atan();
                    let chord = (q.0 - p.0).hypot(q.1 - p.1);
                    if theta >= std::f64::consts::PI {
                        return Err(entity(
                            file,
                            &name("LWPOLYLINE"),
                            p,
                            format!(
                                "a bulge of {} sweeps half a turn or more: not a profile x(z)",
                                s.bulge
                            ),
                        ));
                    }
                    // Positive bulge: counter-clockwise from s to t.
                    let ccw = s.bulge > 0.0;
                    let bulge = if ccw == (p.0 < q.0) {
                        Bulge::In
                    } else {
                        Bulge::Out
                    };
                    Some((chord / (2.0 * (0.5 * theta).sin()), bulge))
                };
                pieces.push(Piece {
                    a: p,
                    b: q,
                    arc,
                    name: format!("{} segment {}", name("LWPOLYLINE"), i + 1),
                });
            }
        }
        dxf::entities::EntityType::Spline(sp) => {
            let points = spline_points(sp, scale, y_scale, options.chordal).map_err(|why| {
                DxfError::Entity {
                    file: file.into(),
                    what: format!("{}: {why}", name("SPLINE")),
                }
            })?;
            for w in points.windows(2) {
                pieces.push(Piece {
                    a: w[0],
                    b: w[1],
                    arc: None,
                    name: name("SPLINE"),
                });
            }
        }
        _ => {}
    }
    Ok(())
}

/// The drawing's length unit in mm.
fn units(drawing: &dxf::Drawing, file: &str) -> Result<Real, DxfError> {
    use dxf::enums::Units;
    let u = drawing.header.default_drawing_units;
    let bad = |what: &str| DxfError::Units {
        file: file.into(),
        code: u as i32,
        what: what.into(),
    };
    match u {
        Units::Millimeters => Ok(1.0),
        Units::Centimeters => Ok(10.0),
        Units::Meters => Ok(1000.0),
        Units::Inches => Ok(25.4),
        Units::Unitless => Err(bad("not stated")),
        other => Err(bad(&format!("{other:?}"))),
    }
}

fn entity(file: &str, name: &str, at: (Real, Real), why: String) -> DxfError {
    DxfError::Entity {
        file: file.into(),
        what: format!("{name} at z = {:.4}, x = {:.4} mm {why}", at.0, at.1),
    }
}

/// The pieces at or above the axis (the half with Y >= 0 of a full
/// outline), the faces (pieces along x) at the ends dropped.
fn upper_half(pieces: Vec<Piece>) -> Vec<Piece> {
    let size = extent(&pieces);
    let eps = crate::tolerance::SAME_RATIO * size;
    let mut out = Vec::new();
    for p in pieces {
        if p.a.1 < -eps || p.b.1 < -eps {
            continue;
        }
        // On the axis: the outline's closing line, not the surface.
        if p.a.1.abs() <= eps && p.b.1.abs() <= eps {
            continue;
        }
        // A face (along x) is kept: `chained` allows one at an end only.
        out.push(p);
    }
    out
}

/// The largest coordinate of the pieces (mm, at least 1): the scale the
/// comparisons of their ends are made at.
fn extent(pieces: &[Piece]) -> Real {
    pieces
        .iter()
        .flat_map(|p| [p.a.0.abs(), p.a.1.abs(), p.b.0.abs(), p.b.1.abs()])
        .fold(1.0, Real::max)
}

/// The pieces as one chain with z increasing, the end faces dropped.
fn chained(mut pieces: Vec<Piece>, file: &str) -> Result<Vec<Piece>, DxfError> {
    let size = extent(&pieces);
    let gap = crate::tolerance::SAME_RATIO * size * 1e3;
    let face = |p: &Piece| (p.b.0 - p.a.0).abs() <= crate::tolerance::SAME_RATIO * size;
    // Start at the least z of the pieces that advance.
    for p in pieces.iter_mut() {
        if p.b.0 < p.a.0 {
            *p = p.clone().reversed();
        }
    }
    let (faces, mut pieces): (Vec<Piece>, Vec<Piece>) = pieces.into_iter().partition(face);
    pieces.sort_by(|a, b| a.a.0.total_cmp(&b.a.0));
    let lo = pieces.iter().map(|p| p.a.0).fold(Real::INFINITY, Real::min);
    let hi = pieces
        .iter()
        .map(|p| p.b.0)
        .fold(Real::NEG_INFINITY, Real::max);
    if let Some(f) = faces.iter().find(|f| f.a.0 > lo + gap && f.a.0 < hi - gap) {
        return Err(entity(file, &f.name, f.a, "is a face inside the outline (along the radius): a profile x(z) has none; the outline must be a function of z between its end faces".into()));
    }
    let mut chain: Vec<Piece> = Vec::with_capacity(pieces.len());
    let mut left = std::collections::VecDeque::from(pieces);
    while let Some(next) = left.pop_front() {
        if let Some(last) = chain.last() {
            let d = (next.a.0 - last.b.0).hypot(next.a.1 - last.b.1);
            if d > gap {
                return Err(DxfError::Entity {
                    file: file.into(),
                    what: format!(
                        "the outline is open: {} ends at z = {:.4}, x = {:.4} mm and the next piece along z, {}, starts {:.4} mm away at z = {:.4}, x = {:.4} mm{}",
                        last.name, last.b.0, last.b.1, next.name, d, next.a.0, next.a.1,
                        if next.a.0 < last.b.0 - gap { " (behind it: two pieces over one stretch of z, or a face inside the outline)" } else { "" }
                    ),
                });
            }
        }
        chain.push(next);
    }
    Ok(chain)
}

/// A SPLINE's points, in mm, within `chordal` of it: the B-spline (its
/// control points, knots and weights; a spline given by fit points only
/// is refused) evaluated by de Boor's algorithm and halved until every
/// chord's middle lies within `chordal` of the curve.
fn spline_points(
    sp: &dxf::entities::Spline,
    scale: Real,
    y_scale: Real,
    chordal: Real,
) -> Result<Vec<(Real, Real)>, String> {
    let p = usize::try_from(sp.degree_of_curve)
        .map_err(|_| format!("degree {} is not a degree", sp.degree_of_curve))?;
    let ctrl: Vec<(Real, Real)> = sp
        .control_points
        .iter()
        .map(|c| (c.x * scale, c.y * scale * y_scale))
        .collect();
    let knots = &sp.knot_values;
    if ctrl.is_empty() {
        return Err(
            "gives fit points only, not its control points: save it with control points (a NURBS)"
                .into(),
        );
    }
    if p == 0 || knots.len() != ctrl.len() + p + 1 {
        return Err(format!(
            "degree {p}, {} control points and {} knots do not make a B-spline",
            ctrl.len(),
            knots.len()
        ));
    }
    let weights: Vec<Real> = if sp.weight_values.len() == ctrl.len() {
        sp.weight_values.clone()
    } else {
        vec![1.0; ctrl.len()]
    };
    let (t0, t1) = (knots[p], knots[ctrl.len()]);
    if !(t1 > t0) {
        return Err("its knots span nothing".into());
    }
    let at = |t: Real| de_boor(p, knots, &ctrl, &weights, t);
    let mut out = vec![at(t0)];
    // Pieces still to judge, nearest first: at least one per knot span,
    // so that no span's bend is missed between two chords' middles.
    let spans: Vec<Real> = (knots[p..=ctrl.len()].windows(2))
        .filter(|w| w[1] > w[0])
        .map(|w| w[0])
        .chain([t1])
        .collect();
    let mut todo: Vec<(Real, Real, u32)> =
        spans.windows(2).rev().map(|w| (w[0], w[1], 0)).collect();
    while let Some((a, b, depth)) = todo.pop() {
        let (pa, pb, pm) = (at(a), at(b), at(0.5 * (a + b)));
        let (dz, dx) = (pb.0 - pa.0, pb.1 - pa.1);
        let len = dz.hypot(dx);
        let off = if len == 0.0 {
            (pm.0 - pa.0).hypot(pm.1 - pa.1)
        } else {
            ((pm.0 - pa.0) * dx - (pm.1 - pa.1) * dz).abs() / len
        };
        if off > chordal && depth < 30 {
            let m = 0.5 * (a + b);
            todo.push((m, b, depth + 1));
            todo.push((a, m, depth + 1));
            continue;
        }
        out.push(pb);
        if out.len() > super::MAX_NODES {
            return Err(format!(
                "needs more than {} points within {chordal} mm",
                super::MAX_NODES
            ));
        }
    }
    Ok(out)
}

/// The rational B-spline of degree `p` at `t` (de Boor's algorithm on
/// homogeneous points).
fn de_boor(p: usize, knots: &[Real], ctrl: &[(Real, Real)], w: &[Real], t: Real) -> (Real, Real) {
    let n = ctrl.len();
    // The span: knots[k] <= t < knots[k + 1], k in p..n.
    let k = (p..n).rfind(|&k| knots[k] <= t).unwrap_or(p);
    let mut d: Vec<[Real; 3]> = (0..=p)
        .map(|j| {
            let i = j + k - p;
            [ctrl[i].0 * w[i], ctrl[i].1 * w[i], w[i]]
        })
        .collect();
    for r in 1..=p {
        for j in (r..=p).rev() {
            let i = j + k - p;
            let den = knots[i + p + 1 - r] - knots[i];
            let alpha = if den == 0.0 {
                0.0
            } else {
                (t - knots[i]) / den
            };
            for c in 0..3 {
                d[j][c] = (1.0 - alpha) * d[j - 1][c] + alpha * d[j][c];
            }
        }
    }
    let [x, y, wt] = d[p];
    (x / wt, y / wt)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;

    /// A DXF (R2000) of `entities` (their group codes as text) in
    /// `$INSUNITS` `units`.
    fn drawing(units: i32, entities: &str) -> Vec<u8> {
        format!(
            "0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1015\n9\n$INSUNITS\n70\n{units}\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n"
        )
        .into_bytes()
    }

    fn line(handle: &str, layer: &str, a: (f64, f64), b: (f64, f64)) -> String {
        format!(
            "0\nLINE\n5\n{handle}\n8\n{layer}\n10\n{}\n20\n{}\n30\n0\n11\n{}\n21\n{}\n31\n0\n",
            a.0, a.1, b.0, b.1
        )
    }

    fn options() -> DxfOptions {
        DxfOptions {
            layer: "profile".into(),
            diameter: false,
            chordal: 1e-4,
        }
    }

    /// A valley the drawing gives (entities A2 and A3 meeting concave at
    /// z = 80 mm): a 5 mm tool's refusal names the entity that ends there,
    /// by its handle, as the profile's source.
    #[test]
    fn where_a_tool_cannot_follow_the_drawing_names_its_entity() {
        let upper = [
            line("A1", "PROFILE", (0.0, 2.0), (5.0, 2.0)),
            line("A2", "PROFILE", (5.0, 2.0), (8.0, 1.5)),
            line("A3", "PROFILE", (8.0, 1.5), (10.0, 2.0)),
        ]
        .concat();
        let p = profile_from_dxf(&drawing(5, &upper), "t.dxf", &options()).unwrap();
        let s = p.source_at(65.0).unwrap();
        assert_eq!(s.label, "LINE #A2 (from z = 50.0000, x = 20.0000 mm)");
        let e = crate::offset::equidistant(&p, 5.0, crate::offset::Side::Outside).unwrap_err();
        assert!(
            e.to_string()
                .contains("z = 80.0000 (a corner: a fillet of at least the tool's radius grinds it; the nominal's LINE #A2"),
            "{e}"
        );
    }

    /// A stepped outline's upper half in centimetres, its faces and the
    /// axis dropped, another layer ignored; a gap, a face inside, unstated
    /// units are refused, naming the entity and where.
    #[test]
    fn an_outline_is_chained_and_its_faults_named() {
        let upper = [
            line("A1", "PROFILE", (0.0, 2.0), (5.0, 2.0)),
            line("A2", "PROFILE", (8.0, 1.5), (5.0, 2.0)),
            line("A3", "PROFILE", (8.0, 1.5), (10.0, 1.5)),
            line("A4", "PROFILE", (0.0, 0.0), (0.0, 2.0)),
            line("A5", "PROFILE", (10.0, 1.5), (10.0, -1.5)),
            line("A6", "PROFILE", (0.0, 0.0), (10.0, 0.0)),
            line("A7", "PROFILE", (0.0, -2.0), (10.0, -1.5)),
            line("B1", "DIMENSIONS", (3.0, 9.0), (4.0, 9.0)),
        ]
        .concat();
        let p = profile_from_dxf(&drawing(5, &upper), "t.dxf", &options()).unwrap();
        assert_eq!(p.z_range(), (0.0, 100.0));
        assert_near!(p.eval(25.0).unwrap(), 20.0, 1e-12);
        assert_near!(p.eval(65.0).unwrap(), 20.0 - 5.0 * 15.0 / 30.0, 1e-12);
        assert_near!(p.eval(90.0).unwrap(), 15.0, 1e-12);

        let gap = [
            line("A1", "PROFILE", (0.0, 2.0), (5.0, 2.0)),
            line("A3", "PROFILE", (8.0, 1.5), (10.0, 1.5)),
        ]
        .concat();
        let e = profile_from_dxf(&drawing(4, &gap), "t.dxf", &options())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("t.dxf: the outline is open: LINE #A1 ends at z = 5.0000")
                && e.contains("LINE #A3"),
            "{e}"
        );
        let face = [
            line("A1", "PROFILE", (0.0, 2.0), (5.0, 2.0)),
            line("F1", "PROFILE", (5.0, 2.0), (5.0, 1.0)),
            line("A3", "PROFILE", (5.0, 1.0), (10.0, 1.0)),
        ]
        .concat();
        let e = profile_from_dxf(&drawing(4, &face), "t.dxf", &options())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("LINE #F1 at z = 5.0000") && e.contains("face inside the outline"),
            "{e}"
        );
        let e = profile_from_dxf(&drawing(0, &gap), "t.dxf", &options())
            .unwrap_err()
            .to_string();
        assert!(e.contains("($INSUNITS 0) are not stated"), "{e}");
        let e = profile_from_dxf(
            &drawing(4, &gap),
            "t.dxf",
            &DxfOptions {
                layer: "OUTLINE".into(),
                ..options()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("layer 'OUTLINE' holds no") && e.contains("PROFILE"),
            "{e}"
        );
    }
}
