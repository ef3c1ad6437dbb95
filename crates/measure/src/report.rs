//! The per-device Markdown document that `rendersim study all --markdown`
//! writes to `docs/measurements/<adapter>.md`: which adapter, how it was
//! measured, a one-line verdict per study, then each study's section.

/// One study's verdict and section.
#[derive(Debug, Clone)]
pub struct StudySection {
    /// `H1`, `H2`, ...
    pub name: String,
    /// One line: what the study found, with its error.
    pub verdict: String,
    /// The study's Markdown section.
    pub markdown: String,
    /// Wall time of measuring and simulating, seconds.
    pub seconds: f64,
}

/// The whole document.
pub fn device_document(adapter: &str, command: &str, notes: &str, sections: &[StudySection]) -> String {
    let mut s = format!(
        "# Measurements: {adapter}\n\n\
         Produced by `{command}` (rendersim {}). Times are medians of repeated passes \
         (timestamp queries around the render pass); counters are pipeline-statistics queries.\n\n",
        env!("CARGO_PKG_VERSION")
    );
    if !notes.is_empty() {
        s += notes.trim_end();
        s += "\n\n";
    }
    s += "| study | verdict | wall time |\n|---|---|---|\n";
    for x in sections {
        s += &format!("| {} | {} | {:.1} s |\n", x.name, x.verdict, x.seconds);
    }
    s += "\n";
    for x in sections {
        s += x.markdown.trim_end();
        s += "\n\n";
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn document_lists_every_study_once() {
        let secs = vec![
            StudySection {
                name: "H1".into(),
                verdict: "exact".into(),
                markdown: "## H1\n\nbody\n".into(),
                seconds: 1.0,
            },
            StudySection {
                name: "H2".into(),
                verdict: "sum".into(),
                markdown: "## H2\n".into(),
                seconds: 2.0,
            },
        ];
        let d = device_document("llvmpipe", "rendersim study all", "A note.", &secs);
        assert!(d.starts_with("# Measurements: llvmpipe"));
        assert_eq!(d.matches("## H1").count(), 1);
        assert!(d.contains("| H2 | sum | 2.0 s |"));
        assert!(d.contains("A note."));
    }
}
