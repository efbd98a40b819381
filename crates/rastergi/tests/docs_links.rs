//! Every relative link in README.md and in docs/**/*.md resolves: the file (or folder) it names
//! exists, and an `#anchor` into a markdown file names one of its headings, slugged as GitHub
//! does (lowercase; letters, digits, spaces, '-' and '_' kept, everything else dropped; spaces
//! to '-'; a repeated heading gets -1, -2, …). Links with a scheme (https:, mailto:, …) are not
//! checked. Code blocks and code spans are not read for links. Milliseconds, no GPU.

use std::collections::HashSet;
use std::fs;
use std::path::{Path, PathBuf};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// README.md and every markdown file under docs/, sorted.
fn markdown_files(root: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut files = vec![root.join("README.md")];
    walk(&root.join("docs"), &mut files);
    files.sort();
    files
}

/// The run of three or more backticks or tildes that opens or closes a fenced code block.
fn fence_marker(line: &str) -> Option<&str> {
    let trimmed = line.trim_start();
    let first = trimmed.chars().next().filter(|&c| c == '`' || c == '~')?;
    let len = trimmed.chars().take_while(|&c| c == first).count();
    (len >= 3 && line.len() - trimmed.len() < 4).then(|| &trimmed[..len])
}

/// The text with fenced code blocks blanked out (newlines kept, so line numbers stay).
fn without_code_blocks(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut fence: Option<String> = None;
    for line in text.split_inclusive('\n') {
        let marker = fence_marker(line);
        match (&fence, marker) {
            (Some(open), Some(m)) if m.starts_with(open.as_str()) && line.trim().len() == m.len() => {
                fence = None;
                out.push_str(&blank(line));
            }
            (Some(_), _) => out.push_str(&blank(line)),
            (None, Some(m)) => {
                fence = Some(m.to_string());
                out.push_str(&blank(line));
            }
            (None, None) => out.push_str(line),
        }
    }
    out
}

/// The prose that links live in: code blocks and code spans blanked out.
fn prose(text: &str) -> String {
    blank_code_spans(&without_code_blocks(text))
}

fn blank(s: &str) -> String {
    s.chars().map(|c| if c == '\n' { '\n' } else { ' ' }).collect()
}

/// Blanks `code spans`: a run of n backticks up to the next run of exactly n within the same
/// paragraph (no blank line between); an unclosed run stays as it is.
fn blank_code_spans(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = chars.clone();
    let run_at = |i: usize| chars[i..].iter().take_while(|&&c| c == '`').count();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' {
            i += 1;
            continue;
        }
        let n = run_at(i);
        let mut j = i + n;
        let mut close = None;
        while j < chars.len() {
            if chars[j] == '\n' {
                let rest = &chars[j + 1..];
                let spaces = rest.iter().take_while(|&&c| c == ' ' || c == '\t').count();
                if matches!(rest.get(spaces), Some('\n') | None) {
                    break; // a blank line ends the paragraph
                }
            }
            if chars[j] == '`' {
                let m = run_at(j);
                if m == n {
                    close = Some(j);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(c) => {
                for ch in &mut out[i..c + n] {
                    if *ch != '\n' {
                        *ch = ' ';
                    }
                }
                i = c + n;
            }
            None => i += n,
        }
    }
    out.into_iter().collect()
}

/// (line, target) of every link: inline links and images `[text](target "title")`, reference
/// definitions `[label]: target`, and HTML `src="…"` / `href="…"`.
fn links(prose: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (n, line) in prose.lines().enumerate() {
        let line_no = n + 1;
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let mut depth = 0;
            let mut end = after.len();
            for (k, c) in after.char_indices() {
                match c {
                    '(' => depth += 1,
                    ')' if depth == 0 => {
                        end = k;
                        break;
                    }
                    ')' => depth -= 1,
                    _ => {}
                }
            }
            let inside = after[..end].trim();
            let target = if let Some(stripped) = inside.strip_prefix('<') {
                stripped.split('>').next().unwrap_or("")
            } else {
                inside.split_whitespace().next().unwrap_or("")
            };
            found.push((line_no, target.to_string()));
            rest = &after[end.min(after.len())..];
        }
        let trimmed = line.trim_start();
        if trimmed.starts_with('[')
            && let Some(close) = trimmed.find("]:")
            && !trimmed[1..close].contains(']')
        {
            let target = trimmed[close + 2..].split_whitespace().next().unwrap_or("");
            found.push((line_no, target.trim_matches(|c| c == '<' || c == '>').to_string()));
        }
        for attr in ["src=\"", "href=\""] {
            let mut rest = line;
            while let Some(at) = rest.find(attr) {
                let after = &rest[at + attr.len()..];
                let end = after.find('"').unwrap_or(after.len());
                found.push((line_no, after[..end].to_string()));
                rest = &after[end..];
            }
        }
    }
    found
}

/// GitHub's anchor for a heading's text.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|&c| c.is_alphanumeric() || c == '-' || c == '_' || c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// A heading's text as GitHub renders it for the slug: links reduced to their text, images
/// and HTML tags dropped (code spans keep their text: only the backticks go, as punctuation).
fn heading_text(raw: &str) -> String {
    let mut out = String::new();
    let mut chars = raw.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '<' => {
                for d in chars.by_ref() {
                    if d == '>' {
                        break;
                    }
                }
            }
            ']' if chars.peek() == Some(&'(') => {
                for d in chars.by_ref() {
                    if d == ')' {
                        break;
                    }
                }
            }
            '!' if chars.peek() == Some(&'[') => {}
            _ => out.push(c),
        }
    }
    out
}

/// Every anchor a markdown file offers: its headings' slugs (repeats numbered) and any HTML
/// `id="…"` or `name="…"`.
fn anchors(text: &str) -> HashSet<String> {
    let prose_lines = without_code_blocks(text);
    let mut seen = HashSet::new();
    let mut counts = std::collections::HashMap::<String, usize>::new();
    let mut add = |text: &str, seen: &mut HashSet<String>| {
        let base = slug(&heading_text(text));
        let count = counts.entry(base.clone()).or_insert(0);
        seen.insert(if *count == 0 { base.clone() } else { format!("{base}-{count}") });
        *count += 1;
    };
    let lines: Vec<&str> = prose_lines.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let hashes = trimmed.chars().take_while(|&c| c == '#').count();
        if (1..=6).contains(&hashes) && line.len() - trimmed.len() < 4 {
            let rest = &trimmed[hashes..];
            if rest.is_empty() || rest.starts_with(' ') || rest.starts_with('\t') {
                let text = rest.trim().trim_end_matches('#').trim_end();
                add(text, &mut seen);
                continue;
            }
        }
        // Setext headings: a paragraph line underlined by === or ---.
        let underline = line.trim();
        if i > 0
            && !underline.is_empty()
            && (underline.chars().all(|c| c == '=') || underline.chars().all(|c| c == '-'))
        {
            let above = lines[i - 1].trim();
            let is_text = !above.is_empty()
                && !above.starts_with(['#', '|', '-', '*', '>', '<'])
                && !above.chars().next().is_some_and(|c| c.is_ascii_digit());
            if is_text {
                add(above, &mut seen);
            }
        }
    }
    for attr in ["id=\"", "name=\""] {
        let mut rest = text;
        while let Some(at) = rest.find(attr) {
            let after = &rest[at + attr.len()..];
            let end = after.find('"').unwrap_or(after.len());
            seen.insert(after[..end].to_string());
            rest = &after[end..];
        }
    }
    seen
}

fn percent_decode(s: &str) -> String {
    let hex = |b: u8| (b as char).to_digit(16).map(|d| d as u8);
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(hi), Some(lo)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push(hi * 16 + lo);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).unwrap_or_else(|_| s.to_string())
}

/// Whether a target is external: a scheme such as `https:` or `mailto:` before any '/'.
fn has_scheme(target: &str) -> bool {
    match target.find(':') {
        Some(colon) => {
            let scheme = &target[..colon];
            !scheme.is_empty()
                && scheme.chars().next().unwrap().is_ascii_alphabetic()
                && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
        }
        None => false,
    }
}

/// The problems with one file's links, as "file:line: message".
fn check_file(root: &Path, file: &Path) -> Vec<String> {
    let text = fs::read_to_string(file).unwrap();
    let name = file.strip_prefix(root).unwrap_or(file).display().to_string();
    let mut problems = Vec::new();
    for (line, target) in links(&prose(&text)) {
        if target.is_empty() {
            problems.push(format!("{name}:{line}: an empty link target"));
            continue;
        }
        if has_scheme(&target) || target.starts_with("//") {
            continue;
        }
        let (path, anchor) = match target.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (target.as_str(), None),
        };
        let path = percent_decode(path.split('?').next().unwrap());
        let resolved = if path.is_empty() {
            file.to_path_buf()
        } else if let Some(from_root) = path.strip_prefix('/') {
            root.join(from_root)
        } else {
            file.parent().unwrap().join(&path)
        };
        if !resolved.exists() {
            problems.push(format!("{name}:{line}: '{target}': {} does not exist", resolved.display()));
            continue;
        }
        if let Some(anchor) = anchor
            && resolved.is_file()
            && resolved.extension().is_some_and(|e| e == "md")
        {
            let anchor = percent_decode(anchor).to_lowercase();
            let offered = anchors(&fs::read_to_string(&resolved).unwrap());
            if !offered.contains(&anchor) {
                problems.push(format!(
                    "{name}:{line}: '{target}': no heading in {} has the anchor #{anchor}",
                    resolved.strip_prefix(root).unwrap_or(&resolved).display()
                ));
            }
        }
    }
    problems
}

#[test]
fn readme_and_docs_links_resolve() {
    let root = repo_root();
    let files = markdown_files(&root);
    assert!(files.len() > 5, "found only {files:?}");
    let mut checked = 0;
    let mut problems = Vec::new();
    for file in &files {
        checked += links(&prose(&fs::read_to_string(file).unwrap())).len();
        problems.extend(check_file(&root, file));
    }
    assert!(checked > 50, "only {checked} links found in {} files: is the parser reading them?", files.len());
    assert!(problems.is_empty(), "{} broken links:\n{}", problems.len(), problems.join("\n"));
}

/// Every page under docs/ can be reached from the README, directly or through other pages.
#[test]
fn every_docs_page_is_reachable_from_the_readme() {
    let root = repo_root();
    let mut reached = HashSet::new();
    let mut queue = vec![root.join("README.md").canonicalize().unwrap()];
    while let Some(file) = queue.pop() {
        if !reached.insert(file.clone()) {
            continue;
        }
        let text = fs::read_to_string(&file).unwrap();
        for (_, target) in links(&prose(&text)) {
            if has_scheme(&target) {
                continue;
            }
            let path = percent_decode(target.split('#').next().unwrap());
            if path.is_empty() {
                continue;
            }
            let Ok(resolved) = file.parent().unwrap().join(&path).canonicalize() else { continue };
            if resolved.is_file() && resolved.extension().is_some_and(|e| e == "md") {
                queue.push(resolved);
            }
        }
    }
    let docs = root.join("docs");
    let unreached: Vec<_> = markdown_files(&root)
        .into_iter()
        .map(|f| f.canonicalize().unwrap())
        .filter(|f| f.starts_with(&docs) && !reached.contains(f))
        .collect();
    assert!(unreached.is_empty(), "docs pages no link leads to from README.md: {unreached:?}");
}

#[test]
fn anchors_follow_githubs_slugs() {
    let text = "# rastergi — design\n\n## Denoiser (`denoise.rs`, `denoise.wgsl`)\n\n\
                ## Formats: OBJ + MTL and glTF 2.0\n\n```sh\n# not a heading\n```\n\n\
                ## Notes\n\n## Notes\n\nSetext\n------\n";
    let offered = anchors(text);
    for a in [
        "rastergi--design",
        "denoiser-denoisers-denoisewgsl",
        "formats-obj--mtl-and-gltf-20",
        "notes",
        "notes-1",
        "setext",
    ] {
        assert!(offered.contains(a), "#{a} missing from {offered:?}");
    }
    assert!(!offered.contains("not-a-heading"));
    let links = links(&prose(
        "See [a](b.md#c) and `[x](not-a-link.md)`, ![i](images/p.png).\n\n[r]: ref.md\n<img src=\"s.png\">",
    ));
    let targets: Vec<_> = links.iter().map(|(_, t)| t.as_str()).collect();
    assert_eq!(targets, ["b.md#c", "images/p.png", "ref.md", "s.png"]);
}
