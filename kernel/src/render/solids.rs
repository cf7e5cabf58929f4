//! A run's exact solids: each body of the part and the tool as a STEP file,
//! beside the meshes (issue 14 §3).

use super::scene::Files;
use crate::family::{PartBody, PartGeometry};
use crate::math::{Mat4, Real, Vec3};
pub use crate::report::SolidFile;
use crate::step::{self, StepError};
use crate::tool::{Tool, ToolShape, WheelOrigin};

/// The STEP files of the part's bodies (in the part frame: bodies of
/// revolution from their profiles, the caliber's roll and the worm swept
/// through their sections) and of a wheel, end mill or thread cutter's
/// blade placed at `tool_pose` as its STL is.
///
/// # Failures
/// A profile that pinches or a tolerance not positive ([`StepError`]).
pub fn step_files(
    parts: &[PartBody],
    tool: &Tool,
    at: &super::scene::ToolAt,
    tol: Real,
) -> Result<(Files, Vec<SolidFile>), StepError> {
    let mut files = Vec::new();
    let mut solids = Vec::new();
    // Each solid: its file's text and its volume from its own outline.
    let mut add = |name: &str,
                   kind: &str,
                   (text, volume): (Result<String, StepError>, Real),
                   (dev, segments): (Real, usize)| {
        let file = format!("{name}.step");
        solids.push(SolidFile {
            name: name.to_owned(),
            kind: kind.to_owned(),
            file: file.clone(),
            volume_mm3: (volume * 1000.0).round() / 1000.0,
            deviation_mm: dev,
            segments,
        });
        files.push((file, text?.into_bytes()));
        Ok::<(), StepError>(())
    };
    let revolution = |name: &str, s: &step::Section, pose: &Mat4| {
        (step::revolution_step(name, s, pose), s.volume())
    };
    for b in parts {
        match &b.geometry {
            PartGeometry::Revolution(p) => {
                let fit = step::profile_section(&b.name, p, tol)?;
                let solid = revolution(&b.name, &fit.section, &Mat4::identity());
                add(&b.name, "part", solid, (fit.deviation, fit.segments))?;
            }
            PartGeometry::Swept(s) => {
                // What the sections already stray by leaves the rest of the
                // tolerance to the fit.
                let strayed = s.body.simplified();
                let fit = step::swept_step(
                    &b.name,
                    "a solid swept through its sections",
                    s.body.sections(),
                    tol - strayed,
                )?;
                add(
                    &b.name,
                    "part",
                    (Ok(fit.text), fit.volume),
                    (fit.deviation + strayed, fit.faces),
                )?;
            }
        }
    }
    let (text, volume, fit) = match tool_step(tool, at, tol)? {
        Some(t) => t,
        None => return Ok((files, solids)),
    };
    let name = if matches!(tool.shape, ToolShape::Wheel(_)) {
        "wheel"
    } else {
        "cutter"
    };
    add(name, "tool", (Ok(text), volume), fit)?;
    Ok((files, solids))
}

/// A tool's STEP text, its volume, and its fit's deviation and faces.
type ToolStep = (String, Real, (Real, usize));

/// The tool's exact solid placed at `at` as its STL is: its STEP text,
/// volume, and deviation and faces where it is fitted (a thread cutter's
/// blade); none for an insert.
///
/// # Failures
/// The blade's fit.
fn tool_step(
    tool: &Tool,
    at: &super::scene::ToolAt,
    tol: Real,
) -> Result<Option<ToolStep>, StepError> {
    let revolution = |name: &str, s: &step::Section, pose: &Mat4| {
        Ok::<_, StepError>(Some((
            step::revolution_step(name, s, pose)?,
            s.volume(),
            (0.0, 0),
        )))
    };
    match tool.shape {
        ToolShape::Wheel(w) => {
            // The wheel's section turns about its own axis, which runs
            // along Z through (D/2, 0, 0) of the wheel frame.
            let r = 0.5 * w.diameter;
            let origin = match tool.origin {
                WheelOrigin::Periphery => 0.0,
                WheelOrigin::Centre => -r,
            };
            let pose = at.pose * Mat4::new_translation(&Vec3::new(r + origin, 0.0, 0.0));
            revolution("wheel", &step::wheel_section(&w), &pose)
        }
        ToolShape::EndMill { diameter, length } => {
            let s = step::cylinder_section(diameter / 2.0, length);
            revolution("cutter", &s, &at.pose)
        }
        ToolShape::ThreadCutter(c) => {
            // The blade as the STL shows it, following the thread it cuts.
            let blade = super::scene::thread_blade(&c, at);
            let fit = step::swept_step("cutter", "a thread cutter's blade", &blade, tol)?;
            Ok(Some((fit.text, fit.volume, (fit.deviation, fit.faces))))
        }
        ToolShape::Insert { .. } => Ok(None),
    }
}
