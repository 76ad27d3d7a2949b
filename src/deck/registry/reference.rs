//! The deck reference (`docs/deck.md`), generated from the registry.

use std::fmt::Write as _;

use super::{BLOCKS, COMMANDS, ELFEN_REFUSED, ENF, EQUATIONS, Naming, SO, block};

/// The deck reference, generated from the registry: one markdown table per block.
pub fn reference_markdown() -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Deck reference\n");
    let _ = writeln!(
        out,
        "Keywords are case-insensitive; `=`, `is` and `are` are interchangeable; `#` and `$` \
         start comments; commas and tabs are whitespace; names are stored lower case, quoted \
         strings keep their case. The `key` column is the canonical snake_case name, which is \
         the TOML field name. In TOML the surface-making commands (`contact surface`, \
         `contact node set`, `skin all blocks`, `begin contact surface`) are entries of \
         `[[contact_definition.surface]]` with `kind = \"contains\" | \"node_set\" | \
         \"skin_all_blocks\" | \"block\"`; `periodicity for` is an entry of \
         `[[contact_definition.periodicity]]` with a `transform` table tagged by `kind`; \
         `enforcement for` lines are `model` entries and `gap conductance coefficient` lines \
         `property` entries of an enforcement. `_` inside a keyword reads as a space \
         (`Buffer_factor` is `buffer factor`). An `=` shown as `[=]` may be left out, as \
         the manuals' syntax lines do; a switch shown as `[= on|off]` alone means on. The \
         `status` column says what seam does: \
         *implemented*; *warns* (kept in the spec, but without effect where the reason \
         says, and a warning says so); *refused* (an error says why). Generated from the \
         keyword registry (`src/deck/registry/`).\n"
    );
    let _ = writeln!(
        out,
        "A deck file is either a contact deck (only `begin contact definition` blocks at the \
         top level; any other line is an error) or a whole Sierra input file (`begin sierra` \
         … `end`, or any file whose contact definitions sit inside other blocks such as \
         `begin procedure` and `begin aria region`). From a Sierra input file seam reads \
         every `begin contact definition` wherever it sits, and skips the other blocks and \
         lines, naming the skipped blocks in one warning (W0103). Aria's \
         `begin toggle block` is refused (E0226) in a contact deck, and in a Sierra input \
         file when an enforcement's `use toggle block` names it (an unused one is only \
         skipped): seam cannot read its schedule; give it as a `[[toggle]]` of the problem \
         file instead.\n"
    );
    let _ = writeln!(
        out,
        "Limits: a deck file (contact deck, whole Sierra input file or TOML) is read up to \
         {} MiB and a Lua file up to {} MiB; a larger file, or a device such as \
         `/dev/zero` that never ends, is refused (E0003) without being read to its end. A \
         deck is UTF-8 text (a leading byte-order mark is accepted); another encoding is \
         refused at the line and column of the first byte that is not UTF-8 (E0004). Blocks \
         nest at most {} deep (E0114). Of the blocks left open at the end of the file, the \
         {} outermost are reported one by one and the rest counted in one more E0101; any \
         run prints at most {} diagnostics, then one line counting the others. Every number \
         has the range given with its command: a value outside it is refused with the range \
         in the message, since it would not fail but change the answer.\n",
        crate::diag::MAX_DECK_BYTES >> 20,
        crate::diag::MAX_LUA_BYTES >> 20,
        crate::deck::tree::MAX_NESTING,
        crate::deck::tree::UNCLOSED_SHOWN,
        crate::diag::MAX_RENDERED,
    );
    for b in BLOCKS {
        let name = match b.naming {
            Naming::Required => " <name>",
            Naming::Optional => " [<name>]",
            Naming::Forbidden => "",
        };
        let _ = writeln!(out, "## `begin {}{name}` … `end`\n", b.phrase);
        let place = match block(b.parent) {
            Some(p) => format!("inside `begin {}`", p.phrase),
            None => "at the top level".to_string(),
        };
        let _ = writeln!(out, "{} Key `{}`; appears {place}.\n", b.description, b.key);
        let _ = writeln!(out, "| command | key | arguments | description | status |");
        let _ = writeln!(out, "|---|---|---|---|---|");
        for sub in BLOCKS.iter().filter(|s| s.parent == b.key) {
            // A block is carried out when any of its commands is.
            let done = COMMANDS
                .iter()
                .any(|c| c.status.is_implemented() && c.blocks.contains(&sub.key));
            let _ = writeln!(
                out,
                "| `begin {}` | `{}` | block | {} | {} |",
                sub.phrase,
                sub.key,
                sub.description,
                if done { "implemented" } else { "refused" }
            );
        }
        for c in COMMANDS.iter().filter(|c| c.blocks.contains(&b.key)) {
            let args = if c.args.is_empty() {
                "—".to_string()
            } else {
                format!("`{}`", c.args.replace('|', "\\|"))
            };
            let _ = writeln!(
                out,
                "| `{}` | `{}` | {} | {} | {} |",
                c.phrase,
                c.key,
                args,
                c.description,
                c.status.describe()
            );
        }
        let _ = writeln!(out);
        if b.key == ENF {
            let _ = writeln!(
                out,
                "Equations of `enforcement for` (Aria's list; any other name is an error, and \
                 one equation may appear once per block). The spec carries every equation; \
                 the deck refuses those seam does not solve.\n"
            );
            let _ = writeln!(out, "| equation | status |");
            let _ = writeln!(out, "|---|---|");
            for (e, st) in EQUATIONS {
                let _ = writeln!(out, "| `{e}` | {} |", st.describe());
            }
            let _ = writeln!(out);
        }
        if b.key == SO {
            let _ = writeln!(
                out,
                "ELFEN contact-set parameters: `Buffer_factor`, `Field_factor` are `buffer \
                 factor`, `field factor`; `Normal_dir_chk_angle` is `normal check angle`; \
                 `Global_update_frequency` is `search update frequency`; `Self_contact_flag` \
                 is `self contact`. The ELFEN parameters below have no counterpart in seam and are \
                 refused (E0224):\n"
            );
            let _ = writeln!(out, "| ELFEN parameter | status |");
            let _ = writeln!(out, "|---|---|");
            for (n, why) in ELFEN_REFUSED {
                let _ = writeln!(out, "| `{n}` | refused: {why} |");
            }
            let _ = writeln!(out);
        }
    }
    out
}
