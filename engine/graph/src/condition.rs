//! Feature conditions, as passes, reads, defines and caveats state them in
//! `enabled_if`: a list whose entries must all hold, each entry a feature
//! (`bloom`), its negation (`!bloom`), or alternatives of those of which one
//! must hold (`spot_lights|!rt_shadows`). A condition that needs "either"
//! says so in one entry; the list stays a conjunction.

use std::collections::BTreeSet;

/// One alternative of an entry: whether it is negated, and the feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Term<'a> {
    /// `!name`: holds when the feature is off.
    pub negated: bool,
    /// The feature's name (empty for a malformed term such as `a||b`).
    pub name: &'a str,
}

/// The alternatives of one `enabled_if` entry, in order.
pub fn terms(entry: &str) -> impl Iterator<Item = Term<'_>> {
    entry.split('|').map(|term| {
        let term = term.trim();
        match term.strip_prefix('!') {
            Some(name) => Term {
                negated: true,
                name: name.trim(),
            },
            None => Term {
                negated: false,
                name: term,
            },
        }
    })
}

/// The features an entry names.
pub fn names(entry: &str) -> impl Iterator<Item = &str> {
    terms(entry).map(|t| t.name)
}

/// Whether one entry holds: one of its alternatives does.
pub fn holds(entry: &str, features: &BTreeSet<String>) -> bool {
    terms(entry).any(|t| !t.name.is_empty() && features.contains(t.name) != t.negated)
}

/// Whether every entry of `conditions` holds (an empty list always does).
pub fn all_hold(conditions: &[String], features: &BTreeSet<String>) -> bool {
    conditions.iter().all(|c| holds(c, features))
}

/// What is wrong with an entry's form, if anything: an empty alternative
/// (`a||b`, a leading or trailing `|`, or `!` alone).
pub fn malformed(entry: &str) -> Option<String> {
    terms(entry).any(|t| t.name.is_empty()).then(|| {
        format!("condition \"{entry}\" has an empty alternative: write features (`a`), negations (`!a`) and alternatives joined by `|` (`a|!b`)")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(names: &[&str]) -> BTreeSet<String> {
        names.iter().map(|n| n.to_string()).collect()
    }

    #[test]
    fn entries_are_features_negations_or_alternatives() {
        let on = set(&["bloom", "suns"]);
        assert!(holds("bloom", &on));
        assert!(!holds("!bloom", &on));
        assert!(holds("!spot_lights", &on));
        assert!(holds("spot_lights|suns", &on));
        assert!(!holds("spot_lights|!suns", &on));
        assert!(holds(" spot_lights | !rt_shadows ", &on));
        assert!(all_hold(&[], &on));
        assert!(all_hold(
            &["bloom".into(), "spot_lights|!rt_shadows".into()],
            &on
        ));
        assert!(!all_hold(
            &["bloom".into(), "spot_lights|rt_shadows".into()],
            &on
        ));
    }

    #[test]
    fn names_and_malformed_entries() {
        assert_eq!(names("a|!b| c").collect::<Vec<_>>(), ["a", "b", "c"]);
        assert_eq!(malformed("a|!b"), None);
        for bad in ["a||b", "|a", "a|", "!", "a|!", ""] {
            assert!(malformed(bad).is_some(), "{bad}");
        }
        // An empty alternative never holds; the others still decide.
        assert!(!holds("!", &set(&[])));
        assert!(holds("a||b", &set(&["b"])));
    }
}
