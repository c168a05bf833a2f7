//! The program in a model's answer: a fenced block (```tad, ```yaml, ```json, or untagged),
//! else the text from the first `use` or `scenario` line to the last closing brace, else a
//! YAML scenario anywhere in the answer. Reasoning in `<think>` tags is skipped.

use tad_db::Language;

/// The program and its notation, or `None` when the answer holds none.
pub fn program(answer: &str) -> Option<(String, Language)> {
    let answer = without_thinking(answer);
    if let Some(found) = fenced(&answer) {
        return Some(found);
    }
    if let Some(start) = tad_start(&answer)
        && let Some(end) = answer.rfind('}')
        && end > start
    {
        return Some((format!("{}\n", answer[start..=end].trim_end()), Language::Tad));
    }
    let trimmed = answer.trim_start();
    if trimmed.starts_with('{') && serde_json::from_str::<serde_json::Value>(trimmed.trim_end()).is_ok() {
        return Some((trimmed.trim_end().to_string(), Language::Yaml));
    }
    tad_yaml::dialect(&answer).map(|_| (answer.to_string(), Language::Yaml))
}

fn without_thinking(answer: &str) -> String {
    let mut out = answer.to_string();
    while let Some(start) = out.find("<think>") {
        match out[start..].find("</think>") {
            Some(len) => out.replace_range(start..start + len + "</think>".len(), ""),
            None => out.truncate(start),
        }
    }
    out
}

fn fenced(answer: &str) -> Option<(String, Language)> {
    let mut rest = answer;
    let mut blocks = Vec::new();
    while let Some(open) = rest.find("```") {
        let after = &rest[open + 3..];
        let line_end = after.find('\n')?;
        let tag = after[..line_end].trim().to_ascii_lowercase();
        let body = &after[line_end + 1..];
        let close = body.find("```").unwrap_or(body.len());
        blocks.push((tag, body[..close].to_string()));
        rest = &body[(close + 3).min(body.len())..];
    }
    for (tag, body) in &blocks {
        let language = match tag.as_str() {
            "tad" | "tadsl" => Some(Language::Tad),
            "yaml" | "yml" | "json" => Some(Language::Yaml),
            "" if tad_syntax::begins_like_tad(body) || tad_start(body).is_some() => Some(Language::Tad),
            "" if tad_yaml::dialect(body).is_some() => Some(Language::Yaml),
            _ => None,
        };
        if let Some(language) = language {
            return Some((body.clone(), language));
        }
    }
    None
}

/// The start of the first line that begins a TAD program (`use`, `scenario`).
fn tad_start(text: &str) -> Option<usize> {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        let begins = (t.starts_with("use ") || t.starts_with("scenario "))
            && t.split_whitespace()
                .nth(1)
                .is_some_and(|w| w.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_'));
        if begins {
            return Some(offset);
        }
        offset += line.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn programs_are_found_in_fences_prose_and_yaml() {
        let fenced = "Sure!\n```tad\nscenario a {\n}\n```\nDone.";
        assert_eq!(program(fenced), Some(("scenario a {\n}\n".into(), Language::Tad)));
        let prose = "Here it is:\nuse national_park\n\nscenario b {\n  ego {\n  }\n}\nHope this helps.";
        assert_eq!(program(prose).unwrap().0, "use national_park\n\nscenario b {\n  ego {\n  }\n}\n");
        let yaml = "```yaml\nenvironment:\n  weather: clear\nactors: {}\n```";
        assert_eq!(program(yaml).unwrap().1, Language::Yaml);
        let json = r#"{"environment":{"weather":"clear"},"road_network":{},"actors":{}}"#;
        assert_eq!(program(json).unwrap().1, Language::Yaml);
        assert_eq!(program("<think>scenario x {}</think>I cannot help."), None);
        assert_eq!(program("The scenario shows a bus."), None);
        assert_eq!(program("```\n"), None);
    }
}
