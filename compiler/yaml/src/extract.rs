//! Finding the YAML inside a raw LLM answer.

use std::ops::Range;

/// Where the YAML is inside a raw LLM answer, as a byte range of `answer`:
///
/// 1. between `<YAML>` and `</YAML>` (case-insensitive). With several blocks the last one
///    that contains a known top-level key wins (else the last one); an unclosed `<YAML>`
///    runs to the end of the text; a code fence inside the block is looked through;
/// 2. else inside a ```` ```yaml ````, ```` ```yml ```` or plain ```` ``` ```` code fence
///    (the same preference among several);
/// 3. else the whole text, if it parses as a YAML mapping with a known top-level key (or
///    with a single key whose value is such a mapping);
/// 4. else, for YAML surrounded by prose without markers, the run of YAML-looking lines
///    that starts at the first line beginning with a known top-level key (`actors:`).
///
/// `None` when there is none of these.
pub fn extract(answer: &str) -> Option<Range<usize>> {
    if let Some(block) = tagged(answer) {
        let inner = &answer[block.clone()];
        if let Some(fence) = fenced(inner)
            && (has_known_key(&inner[fence.clone()]) || !has_known_key(inner))
        {
            return Some(block.start + fence.start..block.start + fence.end);
        }
        return Some(block);
    }
    // a fence whose block holds none of the form's keys while the rest does is stray (a
    // closing fence left after an unfenced answer): the answer is read without it
    if let Some(fence) = fenced(answer)
        && (has_known_key(&answer[fence.clone()]) || !has_known_key(answer))
    {
        return Some(fence);
    }
    let parsed = if crate::parse::too_deep(answer).is_some() {
        None
    } else {
        serde_norway::from_str::<serde_norway::Value>(answer).ok()
    };
    if let Some(serde_norway::Value::Mapping(map)) = parsed {
        let known = |map: &serde_norway::Mapping| map.keys().any(|k| k.as_str().is_some_and(is_known_key));
        // also one wrapper key around the form (`traffic_scenario: {environment: ...}`)
        let wrapped =
            map.len() == 1 && map.values().any(|v| matches!(v, serde_norway::Value::Mapping(inner) if known(inner)));
        if known(&map) || wrapped {
            return Some(0..answer.len());
        }
    }
    unmarked(answer)
}

/// Whether `key` is a top-level key of the forms this crate reads.
fn is_known_key(key: &str) -> bool {
    crate::dialect::is_top_level(key, true)
}

/// Whether some line of `text` starts (after indentation) with a known top-level key.
fn has_known_key(text: &str) -> bool {
    text.lines().any(|l| key_of(l.trim_start()).is_some_and(is_known_key))
}

/// The key of a `key: value` line, if it is one.
fn key_of(line: &str) -> Option<&str> {
    let colon = line.find(':')?;
    let key = line[..colon].trim().trim_matches(['"', '\'']);
    let after = &line[colon + 1..];
    (!key.is_empty() && (after.is_empty() || after.starts_with([' ', '\t', '\r']))).then_some(key)
}

/// Find `needle` (ASCII) case-insensitively in `hay` from byte `from`.
fn find_ci(hay: &str, needle: &str, from: usize) -> Option<usize> {
    let h = hay.as_bytes();
    let n = needle.as_bytes();
    if from > h.len() || n.len() > h.len() {
        return None;
    }
    (from..=h.len() - n.len()).find(|&i| h[i..i + n.len()].eq_ignore_ascii_case(n))
}

fn prefer(blocks: Vec<Range<usize>>, text: &str) -> Option<Range<usize>> {
    blocks.iter().rev().find(|b| has_known_key(&text[(*b).clone()])).or_else(|| blocks.last()).cloned()
}

fn tagged(answer: &str) -> Option<Range<usize>> {
    let mut blocks = Vec::new();
    let mut at = 0;
    while let Some(open) = find_ci(answer, "<yaml>", at) {
        let start = open + "<yaml>".len();
        match find_ci(answer, "</yaml>", start) {
            Some(close) => {
                blocks.push(start..close);
                at = close + "</yaml>".len();
            }
            None => {
                blocks.push(start..answer.len());
                break;
            }
        }
    }
    prefer(blocks, answer)
}

fn fenced(text: &str) -> Option<Range<usize>> {
    let mut blocks = Vec::new();
    let mut offset = 0;
    let mut open: Option<(String, bool, usize)> = None; // (fence, is yaml, content start)
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim();
        let start = offset;
        offset += line.len();
        match &open {
            None => {
                let fence: String = trimmed.chars().take_while(|c| *c == '`' || *c == '~').collect();
                let uniform = fence.chars().all(|c| c == fence.chars().next().unwrap_or('`'));
                if fence.len() >= 3 && uniform {
                    let info = trimmed[fence.len()..].trim().to_ascii_lowercase();
                    let yaml = matches!(info.as_str(), "yaml" | "yml" | "");
                    open = Some((fence, yaml, offset));
                }
            }
            Some((fence, yaml, content)) => {
                if trimmed.starts_with(fence.as_str())
                    && trimmed.trim_start_matches(fence.chars().next().unwrap_or('`')).is_empty()
                {
                    if *yaml {
                        blocks.push(*content..start);
                    }
                    open = None;
                }
            }
        }
    }
    if let Some((_, true, content)) = open {
        blocks.push(content..text.len());
    }
    prefer(blocks, text)
}

fn unmarked(answer: &str) -> Option<Range<usize>> {
    let mut offset = 0;
    let mut start = None;
    let mut end = 0;
    for line in answer.split_inclusive('\n') {
        let line_start = offset;
        offset += line.len();
        let content = line.trim_end_matches(['\n', '\r']);
        match start {
            None => {
                if !content.starts_with([' ', '\t']) && key_of(content).is_some_and(is_known_key) {
                    start = Some(line_start);
                    end = offset;
                }
            }
            Some(_) => {
                let yamlish = content.trim().is_empty()
                    || content.starts_with([' ', '\t', '-', '#'])
                    || key_of(content).is_some_and(|k| !k.contains(' ') || is_known_key(k));
                if !yamlish {
                    break;
                }
                if !content.trim().is_empty() {
                    end = offset;
                }
            }
        }
    }
    start.map(|s| s..end)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn x(answer: &str) -> Option<&str> {
        extract(answer).map(|r| &answer[r])
    }

    #[test]
    fn tags_win_and_the_last_block_wins() {
        assert_eq!(x("a <YAML>\nenvironment:\n  time: day\n</YAML> b"), Some("\nenvironment:\n  time: day\n"));
        assert_eq!(x("<yaml>actors: {}</yaml> then <Yaml>environment: {}</YAML>"), Some("environment: {}"));
        assert_eq!(
            x("wrap it in <YAML>...</YAML>:\n<YAML>\nactors: {}\n</YAML>\n<YAML>...</YAML>"),
            Some("\nactors: {}\n")
        );
        assert_eq!(x("<YAML>\nactors: {}\n"), Some("\nactors: {}\n"));
        assert_eq!(x("<YAML>\n```yaml\nactors: {}\n```\n</YAML>"), Some("actors: {}\n"));
    }

    #[test]
    fn fences() {
        assert_eq!(x("Here:\n```yaml\nactors: {}\n```\nok"), Some("actors: {}\n"));
        assert_eq!(x("```YML\nactors: {}\n```"), Some("actors: {}\n"));
        assert_eq!(x("```\nactors: {}\n```"), Some("actors: {}\n"));
        assert_eq!(x("```python\nactors = 1\n```"), None);
        assert_eq!(x("```yaml\nactors: {}\n"), Some("actors: {}\n"));
    }

    #[test]
    fn whole_text_and_unmarked() {
        assert_eq!(x("environment:\n  weather: clear\n"), Some("environment:\n  weather: clear\n"));
        assert_eq!(x("weather: clear\nlane_num: 2"), Some("weather: clear\nlane_num: 2"));
        assert_eq!(x("hello: world"), None);
        assert_eq!(x(""), None);
        assert_eq!(
            x("Sure! Here it is.\nenvironment:\n  weather: clear\n\nactors:\n  a:\n    type: car\nHope this helps!\n"),
            Some("environment:\n  weather: clear\n\nactors:\n  a:\n    type: car\n")
        );
    }
}
