//! The XML layer: the file and its `<include>`s parsed by `roxmltree` into one owned tree of
//! elements that remember where they start (file, line, column), with `<default>` parameters
//! and `$name` references substituted in every attribute value, and property names in Mitsuba
//! 3's snake_case (`toWorld` → `to_world`, `intIOR` → `int_ior`: an underscore before each
//! capital that follows a lower-case letter or a digit, then lower case), so that the rest of
//! the loader reads format versions 0.5/0.6 and 2/3 alike.
//!
//! Parameters: a caller's definitions (the CLI's `-D name=value`) come first; a `<default
//! name value>` defines its name only where nothing did before (Mitsuba's rule). A `$name` is
//! the longest run of letters, digits and underscores after the `$`; one that nothing defines
//! is an error at the element that uses it. `<include filename>` splices the children of the
//! named file's `<scene>` in its place (its path relative to the including file), at most
//! [`MAX_INCLUDE_DEPTH`] deep.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::scene::Files;
use crate::scene::budget::{Budget, Budgets, MAX_XML_DEPTH};

/// Includes nested deeper than this are refused (an include cycle ends here).
pub const MAX_INCLUDE_DEPTH: usize = 16;
/// Most files a scene and its includes may read.
const MAX_FILES: usize = 256;
/// Bytes of the XML budget per node `roxmltree` may make (an element, a comment, a run of
/// text; it holds about 250 bytes for each): the default 64 MiB allow 2 M nodes.
const BYTES_PER_NODE: u64 = 32;

/// Where an element starts: the index of its file in [`Document::files`], line and column
/// (from 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pos {
    pub file: usize,
    pub line: u32,
    pub column: u32,
}

/// An element with its attributes (values substituted; `name` in snake_case) and children.
#[derive(Clone, Debug)]
pub struct Elem {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Elem>,
    pub pos: Pos,
}

impl Elem {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    /// The element's `name` attribute (a property's name), or "".
    pub fn name(&self) -> &str {
        self.attr("name").unwrap_or("")
    }

    /// The plugin type (`type` attribute), or "".
    pub fn ty(&self) -> &str {
        self.attr("type").unwrap_or("")
    }

    /// Every element of the tree, depth first, this one first.
    pub fn walk<'s>(&'s self, f: &mut impl FnMut(&'s Elem)) {
        f(self);
        self.children.iter().for_each(|c| c.walk(f));
    }
}

/// A parsed scene: its `<scene>` element and the files it came from.
pub struct Document {
    pub root: Elem,
    /// The scene file first, then its includes in the order they were read.
    pub files: Vec<PathBuf>,
    /// The root's `version` attribute: (major, minor).
    pub version: (u32, u32),
}

impl Document {
    /// An error at `pos`: "FILE: line L, column C: message".
    pub fn error_at(files: &[PathBuf], pos: Pos, message: impl std::fmt::Display) -> Error {
        Error::SceneFile {
            path: files.get(pos.file).cloned().unwrap_or_default(),
            message: format!("line {}, column {}: {message}", pos.line, pos.column),
        }
    }

    /// Whether the file is in Mitsuba 0.x's format (camelCase names, 0.6's defaults).
    pub fn legacy(&self) -> bool {
        self.version.0 < 2
    }
}

/// `toWorld` → `to_world`, `intIOR` → `int_ior`; snake_case names are kept.
pub fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let mut previous: Option<char> = None;
    for c in name.chars() {
        if c.is_ascii_uppercase() && previous.is_some_and(|p| p.is_ascii_lowercase() || p.is_ascii_digit()) {
            out.push('_');
        }
        out.push(c.to_ascii_lowercase());
        previous = Some(c);
    }
    out
}

/// Parses the scene at `path` with the caller's parameter definitions, within `budgets`:
/// the files' bytes together ([`Budget::XmlBytes`], checked before each is read), the
/// elements' nesting ([`Budget::XmlDepth`], checked before descending: the tree is converted
/// and dropped recursively) and the text that `$name` substitution and DTD entity references
/// make ([`Budget::Expansion`], checked before it is made). Time is linear in the files' size:
/// an element's line and column are counted on from the previous element's.
pub fn parse(files: Files, path: &Path, defines: &[(String, String)], budgets: &Budgets) -> Result<Document> {
    let mut parser = Parser {
        files,
        paths: Vec::new(),
        params: defines.iter().cloned().collect(),
        budgets: *budgets,
        bytes: 0,
        expanded: 0,
    };
    let (root, version) = parser.file(path, 0, None)?;
    Ok(Document { root, files: parser.paths, version })
}

struct Parser<'a> {
    files: Files<'a>,
    paths: Vec<PathBuf>,
    params: HashMap<String, String>,
    budgets: Budgets,
    /// Bytes of the files read so far.
    bytes: u64,
    /// Bytes made by `$name` substitution so far.
    expanded: u64,
}

/// Line and column (from 1, as `roxmltree` counts them: rows at `\n`, columns in characters)
/// of byte offsets that mostly increase, each counted on from the last one asked for: the
/// elements are visited in the order they are written, so a file costs one pass.
struct Lines<'t> {
    text: &'t str,
    offset: usize,
    line: u32,
    column: u32,
}

impl<'t> Lines<'t> {
    fn new(text: &'t str) -> Lines<'t> {
        Lines { text, offset: 0, line: 1, column: 1 }
    }

    fn at(&mut self, offset: usize) -> (u32, u32) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        if offset < self.offset {
            *self = Lines::new(self.text);
        }
        for c in self.text[self.offset..offset].chars() {
            if c == '\n' {
                self.line += 1;
                self.column = 1;
            } else {
                self.column += 1;
            }
        }
        self.offset = offset;
        (self.line, self.column)
    }

    fn pos(&mut self, node: roxmltree::Node, file: usize) -> Pos {
        let (line, column) = self.at(node.range().start);
        Pos { file, line, column }
    }
}

impl Parser<'_> {
    fn error(&self, pos: Pos, message: impl std::fmt::Display) -> Error {
        Document::error_at(&self.paths, pos, message)
    }

    /// Reads and converts one file; `from` is the `<include>` that names it.
    fn file(&mut self, path: &Path, depth: usize, from: Option<Pos>) -> Result<(Elem, (u32, u32))> {
        let refuse = |parser: &Parser, message: String| match from {
            Some(pos) => parser.error(pos, format!("the included file {}: {message}", path.display())),
            None => Error::SceneFile { path: path.to_path_buf(), message },
        };
        if let Some(what) = self.files.missing(path) {
            let hint = if from.is_some() { "" } else { "; give the path of a Mitsuba scene (.xml) file" };
            return Err(refuse(self, format!("{what}{hint}")));
        }
        if self.files.is_special(path) {
            return Err(refuse(self, "is not a regular file".into()));
        }
        let size = self.files.size(path).unwrap_or(0);
        let detail =
            if self.bytes > 0 { format!("with the {} of the files read before", self.bytes) } else { String::new() };
        self.budgets.check(Budget::XmlBytes, self.bytes + size, &detail).map_err(|m| refuse(self, m))?;
        let bytes = self.files.read(path).map_err(|e| refuse(self, format!("cannot be read: {e}")))?;
        // The file may have grown since its size was taken.
        self.budgets.check(Budget::XmlBytes, self.bytes + bytes.len() as u64, &detail).map_err(|m| refuse(self, m))?;
        self.bytes += bytes.len() as u64;
        let text = String::from_utf8(bytes).map_err(|e| {
            refuse(self, format!("is not UTF-8 text (byte {}); save it as UTF-8", e.utf8_error().valid_up_to()))
        })?;
        let file = self.paths.len();
        self.paths.push(path.to_path_buf());
        let mut lines = Lines::new(&text);
        self.check_entities(&text, file, &mut lines)?;
        let nodes = (self.budgets.xml_bytes / BYTES_PER_NODE).clamp(1 << 16, u32::MAX as u64);
        let options = roxmltree::ParsingOptions { allow_dtd: true, nodes_limit: nodes as u32, ..Default::default() };
        let doc = roxmltree::Document::parse_with_options(&text, options).map_err(|e| {
            if let roxmltree::Error::NodesLimitReached = e {
                let (limit, name) = (self.budgets.xml_bytes, Budget::XmlBytes.name());
                return refuse(
                    self,
                    format!(
                        "has more than {nodes} XML nodes (elements, comments, runs of text), as many as the {name} budget of {limit} allows (one per {BYTES_PER_NODE} bytes); raise it with --budget {name}={} where memory allows",
                        2 * nodes * BYTES_PER_NODE
                    ),
                );
            }
            let at = e.pos();
            let message = e.to_string();
            // roxmltree's messages say " at L:C"; the position is said once, first.
            let message = message.replace(&format!(" at {}:{}", at.row, at.col), "");
            // One line: control characters (a newline roxmltree quotes) written as escapes.
            let message: String = message
                .chars()
                .map(|c| if c.is_control() { c.escape_default().to_string() } else { c.to_string() })
                .collect();
            self.error(Pos { file, line: at.row, column: at.col }, format!("not well-formed XML: {message}"))
        })?;
        let root = doc.root_element();
        let pos = lines.pos(root, file);
        if root.tag_name().name() != "scene" {
            return Err(self.error(
                pos,
                format!("the root element is <{}>; a Mitsuba scene file has <scene>", root.tag_name().name()),
            ));
        }
        let version = match root.attribute("version") {
            Some(v) => parse_version(v).ok_or_else(|| {
                self.error(pos, format!("version \"{v}\" is not a version number such as 0.6.0 or 3.0.0"))
            })?,
            None => {
                log::warn!(
                    "{}: <scene> has no version attribute; read as Mitsuba 0.6 (give version=\"3.0.0\" for Mitsuba 3's defaults)",
                    path.display()
                );
                (0, 6)
            }
        };
        let mut children = Vec::new();
        let mut at = At { file, depth, level: 1, lines: &mut lines };
        self.children(root, &mut at, &mut children)?;
        let attrs = root.attributes().map(|a| (a.name().to_owned(), a.value().to_owned())).collect();
        Ok((Elem { tag: "scene".into(), attrs, children, pos }, version))
    }

    /// Refuses a file whose DTD entities would expand beyond the expansion budget, before
    /// `roxmltree` expands them: each entity's size is its value's with the entities it
    /// names expanded, and every reference after the last declaration counts its entity's
    /// size (an upper bound of what a parser makes of them).
    fn check_entities(&mut self, text: &str, file: usize, lines: &mut Lines) -> Result<()> {
        let Some(entities) = declared_entities(text) else { return Ok(()) };
        let (total, first, name) = entity_references(text, &entities);
        let left = self.budgets.expansion.saturating_sub(self.expanded);
        if total > left {
            let (line, column) = lines.at(first);
            let detail = format!("its references to DTD entities, the first &{name};");
            let e = self.budgets.refusal(Budget::Expansion, self.expanded.saturating_add(total), &detail);
            return Err(self.error(Pos { file, line, column }, format!("the file {e}")));
        }
        self.expanded += total;
        Ok(())
    }

    /// Converts the element children of `node` into `out`, handling `<default>` and
    /// `<include>`.
    fn children(&mut self, node: roxmltree::Node, at: &mut At, out: &mut Vec<Elem>) -> Result<()> {
        for child in node.children().filter(|c| c.is_element()) {
            let pos = at.lines.pos(child, at.file);
            let tag = child.tag_name().name();
            match tag {
                "default" => {
                    let (Some(name), Some(value)) = (child.attribute("name"), child.attribute("value")) else {
                        return Err(self.error(pos, "<default> needs a name and a value"));
                    };
                    if !self.params.contains_key(name) {
                        let value = self.substitute(value, pos)?;
                        self.params.insert(name.to_owned(), value);
                    }
                }
                "include" => {
                    let Some(filename) = child.attribute("filename") else {
                        return Err(self.error(pos, "<include> needs a filename"));
                    };
                    if at.depth + 1 > MAX_INCLUDE_DEPTH || self.paths.len() >= MAX_FILES {
                        return Err(self.error(
                            pos,
                            format!(
                                "includes nest deeper than {MAX_INCLUDE_DEPTH} files or read more than {MAX_FILES} (an include cycle?)"
                            ),
                        ));
                    }
                    let filename = self.substitute(filename, pos)?;
                    let base = self.paths[at.file].parent().unwrap_or(Path::new("")).to_path_buf();
                    let path = resolve(&base, &filename);
                    let (included, _) = self.file(&path, at.depth + 1, Some(pos))?;
                    out.extend(included.children);
                }
                _ => {
                    let level = at.level + 1;
                    if level as u64 > self.budgets.xml_depth.min(MAX_XML_DEPTH) {
                        let e = match self.budgets.xml_depth >= MAX_XML_DEPTH {
                            true => {
                                format!("is nested {level} deep, more than the {MAX_XML_DEPTH} levels rastergi reads")
                            }
                            false => self.budgets.refusal(Budget::XmlDepth, level as u64, ""),
                        };
                        return Err(self.error(pos, format!("<{tag}> {e}")));
                    }
                    let mut attrs = Vec::with_capacity(child.attributes().len());
                    for a in child.attributes() {
                        let mut value = self.substitute(a.value(), pos)?;
                        if a.name() == "name" {
                            value = snake_case(&value);
                        }
                        attrs.push((a.name().to_owned(), value));
                    }
                    let mut elem = Elem { tag: tag.to_owned(), attrs, children: Vec::new(), pos };
                    at.level = level;
                    self.children(child, at, &mut elem.children)?;
                    at.level = level - 1;
                    out.push(elem);
                }
            }
        }
        Ok(())
    }

    /// `value` with every `$name` replaced by its parameter's value; the text made counts
    /// against the expansion budget, its length checked before it is made.
    fn substitute(&mut self, value: &str, pos: Pos) -> Result<String> {
        if !value.contains('$') {
            return Ok(value.to_owned());
        }
        // The pieces: text as it is, or a parameter's value.
        let mut pieces: Vec<&str> = Vec::new();
        let mut rest = value;
        while let Some(i) = rest.find('$') {
            pieces.push(&rest[..i]);
            let after = &rest[i + 1..];
            let n = after.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(after.len());
            if n == 0 {
                pieces.push("$");
                rest = after;
                continue;
            }
            let name = &after[..n];
            match self.params.get(name) {
                Some(v) => pieces.push(v),
                None => {
                    return Err(self.error(
                        pos,
                        format!("${name} is not defined; add <default name=\"{name}\" value=\"...\"/> or pass -D {name}=VALUE"),
                    ));
                }
            }
            rest = &after[n..];
        }
        pieces.push(rest);
        let len: u64 = pieces.iter().map(|p| p.len() as u64).sum();
        let need = self.expanded.saturating_add(len);
        if need > self.budgets.expansion {
            let detail = format!("{len} bytes here, {} made before", self.expanded);
            let e = self.budgets.refusal(Budget::Expansion, need, &detail);
            return Err(self.error(pos, format!("substituting parameters {e}")));
        }
        self.expanded = need;
        Ok(pieces.concat())
    }
}

/// Where the conversion stands: the file, its include depth, the nesting of the element
/// whose children are converted (the root's children are at level 2) and the file's lines.
struct At<'l, 't> {
    file: usize,
    depth: usize,
    level: u32,
    lines: &'l mut Lines<'t>,
}

/// The internal DTD's general entities by name, with their replacement text as written, and
/// the byte offset where the last declaration ends; `None` where the file declares none.
fn declared_entities(text: &str) -> Option<(HashMap<&str, &str>, usize)> {
    const DECLARATION: &str = "<!ENTITY";
    text.find(DECLARATION)?;
    let mut entities = HashMap::new();
    let mut end = 0;
    let mut rest_at = 0;
    while let Some(i) = text[rest_at..].find(DECLARATION) {
        let mut at = rest_at + i + DECLARATION.len();
        let after = |at: usize| text[at..].trim_start();
        let skip = |at: usize| at + (text[at..].len() - after(at).len());
        at = skip(at);
        let parameter = text[at..].starts_with('%');
        if parameter {
            at = skip(at + 1);
        }
        let name_len = text[at..].find(|c: char| c.is_whitespace() || c == '"' || c == '\'' || c == '>').unwrap_or(0);
        let name = &text[at..at + name_len];
        at = skip(at + name_len);
        rest_at = at;
        let Some(quote) = text[at..].chars().next().filter(|c| *c == '"' || *c == '\'') else { continue };
        let Some(len) = text[at + 1..].find(quote) else { break };
        let value = &text[at + 1..at + 1 + len];
        rest_at = at + 1 + len + 1;
        end = rest_at;
        if !parameter && !name.is_empty() {
            entities.entry(name).or_insert(value);
        }
    }
    Some((entities, end))
}

/// The bytes the references `&name;` to `entities` after their declarations expand to (each
/// entity's value with the references to declared entities in it replaced by their expansions
/// in turn, saturating; a cycle counts as nothing and nesting beyond `roxmltree`'s 10 levels
/// as everything, it refuses both), the offset of the first reference and its name.
fn entity_references<'t>(
    text: &'t str,
    (entities, from): &(HashMap<&'t str, &'t str>, usize),
) -> (u64, usize, &'t str) {
    fn references(s: &str) -> impl Iterator<Item = (usize, &str)> {
        s.match_indices('&').filter_map(move |(i, _)| {
            let rest = &s[i + 1..];
            let end = rest.find(';')?;
            let name = &rest[..end];
            (!name.is_empty() && !name.starts_with('#') && !name.contains(char::is_whitespace)).then_some((i, name))
        })
    }
    fn size<'t>(
        name: &'t str,
        entities: &HashMap<&'t str, &'t str>,
        memo: &mut HashMap<&'t str, Option<u64>>,
        depth: u32,
    ) -> u64 {
        // roxmltree expands references 10 deep at most; deeper is refused either way.
        if depth > 10 {
            return u64::MAX;
        }
        match memo.get(name) {
            Some(Some(n)) => return *n,
            Some(None) => return 0,
            None => {}
        }
        let Some(value) = entities.get(name) else { return 0 };
        memo.insert(name, None);
        let mut n = value.len() as u64;
        for (_, inner) in references(value).filter(|(_, name)| entities.contains_key(name)) {
            let reference = inner.len() as u64 + 2;
            n = n.saturating_add(size(inner, entities, memo, depth + 1)).saturating_sub(reference);
        }
        memo.insert(name, Some(n));
        n
    }
    let mut memo = HashMap::new();
    let (mut total, mut first) = (0u64, (0, ""));
    for (i, name) in references(&text[*from..]) {
        if !entities.contains_key(name) {
            continue;
        }
        if first.1.is_empty() {
            first = (from + i, name);
        }
        total = total.saturating_add(size(name, entities, &mut memo, 0));
    }
    (total, first.0, first.1)
}

/// "0.6.0" → (0, 6); "3" → (3, 0).
fn parse_version(v: &str) -> Option<(u32, u32)> {
    let mut parts = v.trim().split('.');
    let major = parts.next()?.parse().ok()?;
    let minor = parts.next().map_or(Some(0), |m| m.parse().ok())?;
    Some((major, minor))
}

/// A path named in a scene file: absolute as is, else relative to `base`; `\` separators
/// (Windows exporters) read as `/`.
pub fn resolve(base: &Path, name: &str) -> PathBuf {
    let name = name.replace('\\', "/");
    let path = Path::new(&name);
    if path.is_absolute() { path.to_path_buf() } else { base.join(path) }
}

/// A plugin element (`<bsdf type=…>`, `<shape …>`) with the record of which of its children
/// have been read, so that the rest can be named in one warning.
pub struct Plugin<'a> {
    pub elem: &'a Elem,
    read: RefCell<Vec<bool>>,
}

impl<'a> Plugin<'a> {
    pub fn new(elem: &'a Elem) -> Plugin<'a> {
        Plugin { elem, read: RefCell::new(vec![false; elem.children.len()]) }
    }

    pub fn ty(&self) -> &'a str {
        self.elem.ty()
    }

    /// The property named `name` (the last one, where a file repeats it), marked as read.
    pub fn get(&self, name: &str) -> Option<&'a Elem> {
        let (i, e) = self.elem.children.iter().enumerate().rev().find(|(_, c)| c.name() == name)?;
        self.read.borrow_mut()[i] = true;
        Some(e)
    }

    /// Whether the property `name` is given (without marking it read).
    pub fn has(&self, name: &str) -> bool {
        self.elem.children.iter().any(|c| c.name() == name)
    }

    /// The nested children with one of these tags (named or not), marked as read.
    pub fn nested(&self, tags: &[&str]) -> Vec<&'a Elem> {
        let mut read = self.read.borrow_mut();
        self.elem
            .children
            .iter()
            .enumerate()
            .filter(|(_, c)| tags.contains(&c.tag.as_str()))
            .map(|(i, c)| {
                read[i] = true;
                c
            })
            .collect()
    }

    /// Marks every child read (a plugin ignored as a whole is named once, not its parts).
    pub fn read_all(&self) {
        self.read.borrow_mut().iter_mut().for_each(|r| *r = true);
    }

    /// The children never read: their names, or their tags where they have none.
    pub fn unread(&self) -> Vec<String> {
        let read = self.read.borrow();
        self.elem
            .children
            .iter()
            .zip(read.iter())
            .filter(|(_, r)| !**r)
            .map(|(c, _)| if c.name().is_empty() { format!("<{}>", c.tag) } else { c.name().to_owned() })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_names_become_snake_case() {
        for (a, b) in [
            ("toWorld", "to_world"),
            ("intIOR", "int_ior"),
            ("fovAxis", "fov_axis"),
            ("sampleCount", "sample_count"),
            ("shapeIndex", "shape_index"),
            ("diffuseReflectance", "diffuse_reflectance"),
            ("to_world", "to_world"),
            ("alpha", "alpha"),
            ("uvscale", "uvscale"),
        ] {
            assert_eq!(snake_case(a), b);
        }
    }

    /// Every element's line and column, counted on from the previous element's, are the ones
    /// roxmltree finds by counting from the start of the text (its `text_pos_at`), in a text
    /// of tabs, CRLF line ends, several elements on a line and characters of several bytes.
    #[test]
    fn element_positions_are_roxmltrees() {
        let text = "<scene version=\"3\">\r\n\t<shape type=\"é\"><a/><b/></shape>\n<!-- ∑ -->  <c>日本<d/></c>\n\n<e\nx=\"1\"/></scene>";
        let doc = roxmltree::Document::parse(text).unwrap();
        let mut lines = Lines::new(text);
        let mut checked = 0;
        for node in doc.descendants().filter(|n| n.is_element()) {
            let expected = doc.text_pos_at(node.range().start);
            assert_eq!(lines.at(node.range().start), (expected.row, expected.col), "<{}>", node.tag_name().name());
            checked += 1;
        }
        assert_eq!(checked, 7);
        // Asked out of order, it counts again from the start.
        let first = doc.root_element().first_element_child().unwrap();
        let expected = doc.text_pos_at(first.range().start);
        assert_eq!(lines.at(first.range().start), (expected.row, expected.col));
    }

    #[test]
    fn entity_expansion_is_bounded_from_above() {
        let text = "<!DOCTYPE s [<!ENTITY a \"xy\"><!ENTITY b '&a;&a;&a;'><!ENTITY c \"&b;&b;&unknown;\"><!ENTITY % p \"zzzz\">]><s>&c;&a;&amp;&#65;</s>";
        let entities = declared_entities(text).unwrap();
        assert_eq!(entities.0.len(), 3);
        // Each entity's value with its references replaced: a = 2, b = 3 × 2 = 6, c = 2 × 6 +
        // 9 (an undeclared name stays as written) = 21; the body names c and a (&amp; and &#65;
        // are not entities).
        let (total, first, name) = entity_references(text, &entities);
        assert_eq!((total, name), (23, "c"));
        assert_eq!(&text[first..first + 3], "&c;");
        assert!(declared_entities("<scene/>").is_none());
    }

    #[test]
    fn versions_parse() {
        assert_eq!(parse_version("0.6.0"), Some((0, 6)));
        assert_eq!(parse_version("3.0.0"), Some((3, 0)));
        assert_eq!(parse_version("2"), Some((2, 0)));
        assert_eq!(parse_version("x"), None);
    }
}
