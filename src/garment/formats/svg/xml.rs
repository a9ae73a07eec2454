//! A small XML reader for the SVG importer: elements, attributes (entities decoded) and their
//! line numbers. Comments, processing instructions, the DOCTYPE, CDATA and text are skipped;
//! namespaces are not resolved (names keep their prefix). Malformed input gives the line and
//! column of the problem, never a panic; elements nested deeper than the limit `max_nesting`
//! are an error at the line of the first one too deep. Nothing here recurses: parsing, and
//! dropping a tree, use explicit stacks.

/// An XML element.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Element {
    /// The tag name, prefix included (`svg:path`).
    pub name: String,
    /// The attributes in document order.
    pub attrs: Vec<(String, String)>,
    /// The child elements.
    pub children: Vec<Element>,
    /// The 1-based line of the start tag.
    pub line: usize,
}

impl Drop for Element {
    /// Drops the subtree with an explicit stack (a deep tree would overflow the call stack).
    fn drop(&mut self) {
        let mut stack = std::mem::take(&mut self.children);
        while let Some(mut el) = stack.pop() {
            stack.append(&mut el.children);
        }
    }
}

impl Element {
    /// The tag name without its namespace prefix.
    pub fn local_name(&self) -> &str {
        self.name.rsplit(':').next().unwrap_or(&self.name)
    }

    /// The value of attribute `name` (exact name, or any prefix followed by `:name`).
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| {
                k == name || (k.ends_with(name) && k[..k.len() - name.len()].ends_with(':'))
            })
            .map(|(_, v)| v.as_str())
    }
}

/// A syntax error: 1-based line and column, and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct XmlError {
    pub line: usize,
    pub column: usize,
    pub message: String,
}

struct Reader<'a> {
    text: &'a str,
    pos: usize,
    /// Byte offsets of the line starts.
    line_starts: Vec<usize>,
}

impl Reader<'_> {
    fn position(&self, at: usize) -> (usize, usize) {
        let at = at.min(self.text.len());
        let line = self.line_starts.partition_point(|&s| s <= at);
        let start = self.line_starts[line - 1];
        let column = self.text.get(start..at).map_or(0, |l| l.chars().count()) + 1;
        (line, column)
    }

    fn error(&self, at: usize, message: impl Into<String>) -> XmlError {
        let (line, column) = self.position(at);
        XmlError {
            line,
            column,
            message: message.into(),
        }
    }

    fn rest(&self) -> &str {
        &self.text[self.pos..]
    }

    fn skip_past(&mut self, end: &str, what: &str) -> Result<(), XmlError> {
        match self.rest().find(end) {
            Some(i) => {
                self.pos += i + end.len();
                Ok(())
            }
            None => Err(self.error(self.pos, format!("unterminated {what}"))),
        }
    }

    fn skip_ws(&mut self) {
        let trimmed = self.rest().trim_start();
        self.pos = self.text.len() - trimmed.len();
    }

    fn name(&mut self) -> Result<String, XmlError> {
        let len = self
            .rest()
            .find(|c: char| c.is_whitespace() || matches!(c, '/' | '>' | '=' | '<' | '"' | '\''))
            .unwrap_or(self.rest().len());
        if len == 0 {
            return Err(self.error(self.pos, "expected a name"));
        }
        let name = self.rest()[..len].to_string();
        self.pos += len;
        Ok(name)
    }

    /// Skips a `<!DOCTYPE …>` declaration, internal subset included.
    fn skip_doctype(&mut self) -> Result<(), XmlError> {
        let start = self.pos;
        let mut depth = 0i32;
        for (i, c) in self.rest().char_indices() {
            match c {
                '[' => depth += 1,
                ']' => depth -= 1,
                '>' if depth <= 0 => {
                    self.pos += i + 1;
                    return Ok(());
                }
                _ => {}
            }
        }
        Err(self.error(start, "unterminated <!DOCTYPE"))
    }

    /// Reads a start tag (after its `<`); returns the element and whether it is self-closing.
    fn start_tag(&mut self, tag_start: usize) -> Result<(Element, bool), XmlError> {
        let name = self.name()?;
        let mut el = Element {
            name,
            attrs: Vec::new(),
            children: Vec::new(),
            line: self.position(tag_start).0,
        };
        loop {
            self.skip_ws();
            let rest = self.rest();
            if rest.starts_with("/>") {
                self.pos += 2;
                return Ok((el, true));
            }
            if rest.starts_with('>') {
                self.pos += 1;
                return Ok((el, false));
            }
            if rest.is_empty() {
                return Err(self.error(tag_start, format!("unterminated start tag <{}", el.name)));
            }
            let key = self.name()?;
            self.skip_ws();
            if !self.rest().starts_with('=') {
                return Err(self.error(self.pos, format!("expected '=' after attribute {key}")));
            }
            self.pos += 1;
            self.skip_ws();
            let quote = match self.rest().chars().next() {
                Some(q @ ('"' | '\'')) => q,
                _ => {
                    return Err(self.error(
                        self.pos,
                        format!("expected a quoted value for attribute {key}"),
                    ))
                }
            };
            self.pos += 1;
            let end = self.rest().find(quote).ok_or_else(|| {
                self.error(self.pos, format!("unterminated value of attribute {key}"))
            })?;
            let value = decode_entities(&self.rest()[..end]);
            self.pos += end + 1;
            el.attrs.push((key, value));
        }
    }
}

fn decode_entities(s: &str) -> String {
    if !s.contains('&') {
        return s.to_string();
    }
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find('&') {
        out.push_str(&rest[..i]);
        rest = &rest[i..];
        let decoded = rest.find(';').and_then(|j| {
            let ent = &rest[1..j];
            let c = match ent {
                "lt" => Some('<'),
                "gt" => Some('>'),
                "amp" => Some('&'),
                "quot" => Some('"'),
                "apos" => Some('\''),
                _ if ent.starts_with("#x") || ent.starts_with("#X") => {
                    u32::from_str_radix(&ent[2..], 16)
                        .ok()
                        .and_then(char::from_u32)
                }
                _ if ent.starts_with('#') => ent[1..].parse().ok().and_then(char::from_u32),
                _ => None,
            };
            c.map(|c| (c, j))
        });
        match decoded {
            Some((c, j)) => {
                out.push(c);
                rest = &rest[j + 1..];
            }
            None => {
                out.push('&');
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// Parses an XML document and returns its root element.
pub(crate) fn parse(text: &str) -> Result<Element, XmlError> {
    let line_starts = std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect();
    let mut r = Reader {
        text,
        pos: 0,
        line_starts,
    };
    let max_depth = crate::limits::get().max_nesting;
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    while let Some(i) = r.rest().find('<') {
        r.pos += i;
        let tag_start = r.pos;
        let rest = r.rest();
        if rest.starts_with("<!--") {
            r.skip_past("-->", "comment")?;
        } else if rest.starts_with("<![CDATA[") {
            r.skip_past("]]>", "CDATA section")?;
        } else if rest.starts_with("<!") {
            r.skip_doctype()?;
        } else if rest.starts_with("<?") {
            r.skip_past("?>", "processing instruction")?;
        } else if rest.starts_with("</") {
            r.pos += 2;
            let name = r.name()?;
            r.skip_ws();
            if !r.rest().starts_with('>') {
                return Err(r.error(r.pos, format!("expected '>' to end </{name}")));
            }
            r.pos += 1;
            let el = stack
                .pop()
                .ok_or_else(|| r.error(tag_start, format!("unexpected end tag </{name}>")))?;
            if el.name != name {
                return Err(r.error(
                    tag_start,
                    format!(
                        "end tag </{name}> does not match <{}> of line {}",
                        el.name, el.line
                    ),
                ));
            }
            match stack.last_mut() {
                Some(parent) => parent.children.push(el),
                None => {
                    root.get_or_insert(el);
                }
            }
        } else {
            r.pos += 1;
            let (el, closed) = r.start_tag(tag_start)?;
            if closed {
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => {
                        root.get_or_insert(el);
                    }
                }
            } else {
                if stack.len() as u64 >= max_depth {
                    return Err(r.error(
                        tag_start,
                        format!(
                            "<{}> is nested {} elements deep, over the limit max_nesting = {max_depth} (raise it with `emilion run --limit max_nesting=N`)",
                            el.name,
                            stack.len() + 1
                        ),
                    ));
                }
                stack.push(el);
            }
        }
    }
    if let Some(open) = stack.last() {
        return Err(XmlError {
            line: open.line,
            column: 1,
            message: format!("element <{}> is never closed", open.name),
        });
    }
    root.ok_or_else(|| r.error(text.len(), "no root element"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_elements_attributes_and_lines() {
        let doc = "<?xml version=\"1.0\"?>\n<!-- c -->\n<svg a='1 &amp; 2'>\n <g id=\"x\"><path d=\"M 0 0\"/>text</g>\n<style><![CDATA[ <g> ]]></style></svg>";
        let root = parse(doc).unwrap();
        assert_eq!(root.name, "svg");
        assert_eq!(root.attr("a"), Some("1 & 2"));
        assert_eq!(root.children[0].children[0].line, 4);
        assert_eq!(root.children.len(), 2);
    }

    #[test]
    fn elements_nested_past_max_nesting_are_an_error_at_their_line() {
        let deep = format!("<svg>\n{}{}</svg>", "<g>\n".repeat(300), "</g>".repeat(300));
        let e = parse(&deep).unwrap_err();
        // the svg is level 1, so the 256th <g> (line 257) is the first too deep
        assert_eq!(e.line, 257, "{e:?}");
        assert!(e.message.contains("max_nesting = 256"), "{e:?}");
        let ok = format!("<svg>{}{}</svg>", "<g>".repeat(255), "</g>".repeat(255));
        assert!(parse(&ok).is_ok());
    }

    #[test]
    fn a_deep_tree_drops_without_recursion() {
        // deeper than any test thread's stack allows for a recursive drop
        let mut el = Element::default();
        for _ in 0..1_000_000 {
            let mut parent = Element::default();
            parent.children.push(el);
            el = parent;
        }
        drop(el);
    }

    #[test]
    fn reports_positions_of_errors() {
        let e = parse("<svg>\n<g>\n</svg>").unwrap_err();
        assert_eq!((e.line, e.column), (3, 1), "{e:?}");
        let e = parse("<svg>\n  <g id=\"a></svg>").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(parse("<svg><g></g>").is_err());
        assert!(parse("").is_err());
        let mut el = Element::default();
        el.attrs.push(("xlink:href".into(), "#n".into()));
        assert_eq!(el.attr("href"), Some("#n"));
    }
}
