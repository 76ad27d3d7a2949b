//! The deck's diagnostic codes, and those of reading any input file (E000x): one
//! constant per meaning, never reused.
//!
//! | code  | severity | meaning |
//! |-------|----------|---------|
//! | E0001 | error    | an input file cannot be read (missing, unreadable, a directory) |
//! | E0003 | error    | an input file (deck, problem file, Lua file) larger than seam reads |
//! | E0004 | error    | an input file that is not UTF-8 text (points at the first bad byte) |
//! | E0101 | error    | `begin` block not closed before the end of the file |
//! | E0102 | error    | `end` line names a block type or name other than the open block |
//! | E0103 | error    | unknown line command in this block (with did-you-mean) |
//! | E0104 | error    | known line command used in a block where it is not allowed |
//! | E0105 | error    | unknown block type after `begin` (with did-you-mean) |
//! | E0106 | error    | block opened somewhere it may not appear |
//! | E0107 | error    | `end` with no open block |
//! | E0108 | error    | quoted string not closed on its line |
//! | E0109 | error    | line outside every block |
//! | E0110 | error    | command is missing a word or value it needs |
//! | E0111 | error    | block needs a name, or has a name it may not have |
//! | E0112 | error    | unexpected extra words at the end of a command |
//! | E0113 | error    | a block that may appear once per definition appears twice |
//! | E0114 | error    | blocks nested deeper than seam reads ([`super::MAX_NESTING`]) |
//! | E0150 | error    | TOML syntax or type error |
//! | E0201 | error    | value should be a (finite) number or integer but is not |
//! | E0202 | error    | `Auto Subset … Angle` not positive |
//! | E0203 | error    | `Auto Subset … Number Of Subsets` not positive |
//! | E0204 | error    | `Subset` and `Auto Subset` in the same `Contact Surface` block |
//! | E0205 | error    | more than one `Auto Subset` in one `Contact Surface` block |
//! | E0206 | error    | zero normal vector in `Subset … With Normal` |
//! | E0207 | error    | `Opposed Normal Threshold Angle` below 90 degrees (or above 180) |
//! | E0208 | error    | `Normal Tolerance` not positive |
//! | E0209 | error    | the same surface name defined twice in one contact definition |
//! | E0210 | error    | unknown `Output Rule` value |
//! | E0211 | error    | wrong number of values (point, offset, axis, center) |
//! | E0212 | error    | on/off switch with another value |
//! | E0213 | error    | unknown `Contact Type` value |
//! | E0214 | error    | unknown periodicity transform, or a transform missing a part |
//! | E0215 | error    | interaction names an enforcement that is not defined |
//! | E0216 | error    | a value that must be positive is not (penalty scale factor) |
//! | E0217 | error    | a word outside the command's list of choices (overclosure treatment) |
//! | E0218 | error    | material-model line seam recognises but cannot use (needs an equation it does not solve) |
//! | E0219 | error    | `Enforcement For` an equation of Aria's list that seam does not solve |
//! | E0220 | error    | `Enforcement For` an equation name not in Aria's list (with did-you-mean) |
//! | E0221 | error    | the same equation twice in one enforcement block |
//! | E0222 | error    | `Contact Pressure` and `Contact Surface Pressure` in one enforcement block |
//! | E0223 | error    | argument key the enforcement model does not take (with did-you-mean) |
//! | E0224 | error    | ELFEN contact-set parameter with no counterpart in seam |
//! | E0225 | error    | unknown material property of an enforcement (TOML `property`), or one with its own field |
//! | E0226 | error    | `begin toggle block`: in a contact deck, or used by an enforcement of a Sierra input file (its schedule cannot be read) |
//! | E0227 | error    | a number outside its documented range (the range is in the message) |
//! | E0228 | error    | a line of an equation's enforcement (`Partition Coefficient`, `Offset Species`) in a block that does not enforce that equation |
//! | W0101 | warning  | deprecated alias (`Slave Variable`) |
//! | W0102 | warning  | single-valued command given twice; the last one wins |
//! | W0103 | warning  | blocks and lines of a Sierra input file skipped (not contact input) |

pub const CANNOT_READ: &str = "E0001";
pub const TOO_LARGE: &str = "E0003";
pub const NOT_UTF8: &str = "E0004";
pub const UNCLOSED_BLOCK: &str = "E0101";
pub const MISMATCHED_END: &str = "E0102";
pub const UNKNOWN_KEYWORD: &str = "E0103";
pub const WRONG_BLOCK: &str = "E0104";
pub const UNKNOWN_BLOCK: &str = "E0105";
pub const MISPLACED_BLOCK: &str = "E0106";
pub const STRAY_END: &str = "E0107";
pub const UNTERMINATED_STRING: &str = "E0108";
pub const OUTSIDE_BLOCK: &str = "E0109";
pub const MISSING_ARGUMENT: &str = "E0110";
pub const BLOCK_NAME: &str = "E0111";
pub const EXTRA_WORDS: &str = "E0112";
pub const DUPLICATE_BLOCK: &str = "E0113";
pub const TOO_DEEP: &str = "E0114";
pub const TOML_ERROR: &str = "E0150";
pub const NOT_A_NUMBER: &str = "E0201";
pub const NONPOSITIVE_ANGLE: &str = "E0202";
pub const NONPOSITIVE_SUBSETS: &str = "E0203";
pub const SUBSET_AND_AUTO: &str = "E0204";
pub const SECOND_AUTO_SUBSET: &str = "E0205";
pub const ZERO_NORMAL: &str = "E0206";
pub const OPPOSED_ANGLE: &str = "E0207";
pub const NORMAL_TOLERANCE: &str = "E0208";
pub const DUPLICATE_SURFACE: &str = "E0209";
pub const OUTPUT_RULE: &str = "E0210";
pub const VALUE_COUNT: &str = "E0211";
pub const ON_OFF: &str = "E0212";
pub const CONTACT_TYPE: &str = "E0213";
pub const PERIODICITY: &str = "E0214";
pub const UNKNOWN_ENFORCEMENT: &str = "E0215";
pub const NOT_POSITIVE: &str = "E0216";
pub const BAD_CHOICE: &str = "E0217";
pub const REFUSED_MATERIAL_MODEL: &str = "E0218";
pub const REFUSED_EQUATION: &str = "E0219";
pub const UNKNOWN_EQUATION: &str = "E0220";
pub const DUPLICATE_EQUATION: &str = "E0221";
pub const TWO_PRESSURES: &str = "E0222";
pub const UNKNOWN_MODEL_KEY: &str = "E0223";
pub const ELFEN_REFUSED: &str = "E0224";
pub const UNKNOWN_PROPERTY: &str = "E0225";
pub const TOGGLE_BLOCK: &str = "E0226";
pub const OUT_OF_RANGE: &str = "E0227";
pub const NOT_THIS_EQUATION: &str = "E0228";
pub const DEPRECATED_ALIAS: &str = "W0101";
pub const REPEATED_COMMAND: &str = "W0102";
pub const SKIPPED_BLOCKS: &str = "W0103";

/// Every code above, for tests and tools that list them.
pub const ALL: &[&str] = &[
    CANNOT_READ,
    TOO_LARGE,
    NOT_UTF8,
    UNCLOSED_BLOCK,
    MISMATCHED_END,
    UNKNOWN_KEYWORD,
    WRONG_BLOCK,
    UNKNOWN_BLOCK,
    MISPLACED_BLOCK,
    STRAY_END,
    UNTERMINATED_STRING,
    OUTSIDE_BLOCK,
    MISSING_ARGUMENT,
    BLOCK_NAME,
    EXTRA_WORDS,
    DUPLICATE_BLOCK,
    TOO_DEEP,
    TOML_ERROR,
    NOT_A_NUMBER,
    NONPOSITIVE_ANGLE,
    NONPOSITIVE_SUBSETS,
    SUBSET_AND_AUTO,
    SECOND_AUTO_SUBSET,
    ZERO_NORMAL,
    OPPOSED_ANGLE,
    NORMAL_TOLERANCE,
    DUPLICATE_SURFACE,
    OUTPUT_RULE,
    VALUE_COUNT,
    ON_OFF,
    CONTACT_TYPE,
    PERIODICITY,
    UNKNOWN_ENFORCEMENT,
    NOT_POSITIVE,
    BAD_CHOICE,
    REFUSED_MATERIAL_MODEL,
    REFUSED_EQUATION,
    UNKNOWN_EQUATION,
    DUPLICATE_EQUATION,
    TWO_PRESSURES,
    UNKNOWN_MODEL_KEY,
    ELFEN_REFUSED,
    UNKNOWN_PROPERTY,
    TOGGLE_BLOCK,
    OUT_OF_RANGE,
    NOT_THIS_EQUATION,
    DEPRECATED_ALIAS,
    REPEATED_COMMAND,
    SKIPPED_BLOCKS,
];

#[cfg(test)]
mod tests {
    use super::ALL;

    #[test]
    fn codes_are_unique_and_documented_in_the_table() {
        let source = include_str!("codes.rs");
        for (i, code) in ALL.iter().enumerate() {
            assert!(!ALL[i + 1..].contains(code), "{code} is used twice");
            assert!(
                source.contains(&format!("//! | {code} |")),
                "{code} is missing from the table"
            );
            let consts = source.matches(&format!("&str = \"{code}\";")).count();
            assert_eq!(consts, 1, "{code} should have exactly one constant");
        }
        let rows = source
            .lines()
            .filter(|l| l.starts_with("//! | E") || l.starts_with("//! | W"))
            .count();
        assert_eq!(rows, ALL.len(), "the table and ALL list different codes");
    }
}
