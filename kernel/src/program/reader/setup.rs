//! The machine's setup words a block may hold: diameter or radius
//! programming and the feed's group, each once, before the first move,
//! and as the machine's setup says (a program read as it stands may
//! switch between diameter and radius by Sinumerik's words anywhere).

use super::{Block, Reader, Said, State};
use crate::program::lint::LintError;
use pilgrim_plugin_abi::types::Radial;

impl Reader<'_> {
    /// The setup words block `b` holds (`said`; `k` moves read before it)
    /// taken into the modal state `st`.
    ///
    /// # Failures
    /// One among the moves, twice, or other than the setup's.
    pub(super) fn setup_words(
        &self,
        st: &mut State,
        b: &Block,
        k: usize,
        said: &Said,
    ) -> Result<(), LintError> {
        let program = self.program;
        for (diameter, word) in &said.radial {
            let diameter = *diameter;
            let want = program.setup.radial.map(|r| r == Radial::Diameter);
            // A program read as it stands may switch by the dialect's own
            // words among its moves: its radial axis's values are taken
            // into the setup's programming (`Reader::radial_scale`).
            let switch = self.reading && self.radial.is_some() && want.is_some();
            let once = !switch && (k > 0 || st.radial.is_some());
            if once || (!switch && want != Some(diameter)) {
                return Err(self.err(
                    self.place(b, k),
                    format!(
                        "{word}: {} where the machine's setup {}",
                        if diameter {
                            "diameter programming"
                        } else {
                            "radius programming"
                        },
                        match (want, once) {
                            (_, true) => "sets it once, before the moves",
                            (Some(true), _) => "programs the radial axis on diameter",
                            (Some(false), _) => "programs the radial axis on radius",
                            (None, _) => "says nothing of it",
                        }
                    ),
                ));
            }
            st.radial = Some(diameter);
        }
        let group = program.setup.feed_group.join(",");
        for list in &said.feed_group {
            if k > 0 || st.feed_group || *list != group {
                return Err(self.err(
                    self.place(b, k),
                    format!(
                        "FGROUP({list}) where the machine's setup groups the feed over ({group}), once, before the moves"
                    ),
                ));
            }
            st.feed_group = true;
        }
        Ok(())
    }
}
