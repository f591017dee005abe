//! The head model is the machine file's optional `[head]` table ([`towpath_machine::Head`]);
//! this module checks that its documentation in `docs/motion.md` stays true.

#[cfg(test)]
mod tests {
    use towpath_machine::Head;

    /// Every key of the head is documented in docs/motion.md, and its example is a valid head.
    #[test]
    fn keys_are_documented() {
        let docs = include_str!("../../../docs/motion.md");
        for k in ["radius", "bottom", "top"] {
            assert!(docs.contains(&format!("`{k}`")), "head key {k} is not documented");
        }
        let example = docs.split("```toml\n").nth(1).and_then(|s| s.split("```").next()).unwrap();
        let table: toml::Table = toml::from_str(example).unwrap();
        let head: Head = table["head"].clone().try_into().unwrap();
        head.validate().unwrap();
    }
}
