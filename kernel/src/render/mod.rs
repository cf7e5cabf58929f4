//! What a run shows: the report's page (`page`), the 3-D scene at a block
//! and its playback (`scene`, `spin`: the part turning as the program turns
//! it) and the exact solids for CAD (`solids`). It reads the report, the
//! program and the machine's bodies; it knows no family (a verification's
//! section of the page comes from the registry, `crate::families::kind`).

pub mod page;
pub mod scene;
pub mod solids;
pub mod spin;
