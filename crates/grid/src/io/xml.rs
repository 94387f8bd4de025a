//! A small XML reader for VTK files: elements, attributes, text; comments, the `<?xml?>`
//! declaration and `<!DOCTYPE>` are skipped. No namespaces, no entities beyond the five
//! predefined ones and numeric character references.

/// One XML element.
#[derive(Debug)]
pub(crate) struct Element<'a> {
    pub name: &'a str,
    pub attrs: Vec<(&'a str, String)>,
    pub children: Vec<Element<'a>>,
    /// The text directly inside the element (from the end of the start tag to the first
    /// child or the end tag).
    pub text: &'a str,
    /// Byte offset of the start tag and of `text`.
    pub offset: usize,
    pub text_offset: usize,
}

impl<'a> Element<'a> {
    pub(crate) fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| *k == name)
            .map(|(_, v)| v.as_str())
    }
    pub(crate) fn child(&self, name: &str) -> Option<&Element<'a>> {
        self.children.iter().find(|c| c.name == name)
    }
    pub(crate) fn children_named<'s>(
        &'s self,
        name: &'s str,
    ) -> impl Iterator<Item = &'s Element<'a>> + 's {
        self.children.iter().filter(move |c| c.name == name)
    }
}

/// Maps byte offsets to 1-based line numbers.
pub(crate) struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub(crate) fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(
            text.bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| i + 1),
        );
        Self { starts }
    }
    pub(crate) fn line(&self, offset: usize) -> usize {
        self.starts.partition_point(|&s| s <= offset)
    }
}

/// A parse failure at a byte offset.
pub(crate) struct XmlError {
    pub offset: usize,
    pub what: String,
}

fn err<T>(offset: usize, what: impl Into<String>) -> Result<T, XmlError> {
    Err(XmlError {
        offset,
        what: what.into(),
    })
}

fn is_name_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.' | b':') || b >= 0x80
}

fn unescape(s: &str, offset: usize) -> Result<String, XmlError> {
    if !s.contains('&') {
        return Ok(s.to_string());
    }
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(p) = rest.find('&') {
        out.push_str(&rest[..p]);
        let Some(e) = rest[p..].find(';') else {
            return err(offset, "unterminated `&` entity in attribute");
        };
        let ent = &rest[p + 1..p + e];
        let ch = match ent {
            "amp" => '&',
            "lt" => '<',
            "gt" => '>',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code = if let Some(h) = ent.strip_prefix("#x") {
                    u32::from_str_radix(h, 16).ok()
                } else if let Some(d) = ent.strip_prefix('#') {
                    d.parse().ok()
                } else {
                    None
                };
                match code.and_then(char::from_u32) {
                    Some(c) => c,
                    None => return err(offset, format!("unknown entity `&{ent};`")),
                }
            }
        };
        out.push(ch);
        rest = &rest[p + e + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Parse a document and return its root element.
pub(crate) fn parse(text: &str) -> Result<Element<'_>, XmlError> {
    let b = text.as_bytes();
    let mut pos = 0;
    let mut stack: Vec<Element<'_>> = Vec::new();
    let mut root: Option<Element<'_>> = None;
    loop {
        // Text up to the next tag.
        let next = text[pos..].find('<').map(|p| pos + p);
        let Some(lt) = next else {
            if !text[pos..].trim().is_empty() && stack.is_empty() {
                return err(pos, "text after the root element");
            }
            break;
        };
        if let Some(top) = stack.last_mut()
            && top.children.is_empty()
            && top.text.is_empty()
        {
            top.text = &text[pos..lt];
            top.text_offset = pos;
        }
        pos = lt;
        let rest = &text[pos..];
        if rest.starts_with("<!--") {
            let Some(e) = rest.find("-->") else {
                return err(pos, "unterminated comment");
            };
            pos += e + 3;
        } else if rest.starts_with("<?") {
            let Some(e) = rest.find("?>") else {
                return err(pos, "unterminated `<?`");
            };
            pos += e + 2;
        } else if rest.starts_with("<!") {
            let Some(e) = rest.find('>') else {
                return err(pos, "unterminated `<!`");
            };
            pos += e + 1;
        } else if rest.starts_with("</") {
            let start = pos + 2;
            let mut q = start;
            while q < b.len() && is_name_byte(b[q]) {
                q += 1;
            }
            let name = &text[start..q];
            while q < b.len() && b[q].is_ascii_whitespace() {
                q += 1;
            }
            if q >= b.len() || b[q] != b'>' {
                return err(pos, format!("malformed end tag `</{name}`"));
            }
            let Some(el) = stack.pop() else {
                return err(pos, format!("end tag `</{name}>` without a start tag"));
            };
            if el.name != name {
                return err(
                    pos,
                    format!("end tag `</{name}>` does not match `<{}>`", el.name),
                );
            }
            pos = q + 1;
            match stack.last_mut() {
                Some(parent) => parent.children.push(el),
                None => root = Some(el),
            }
        } else {
            if root.is_some() {
                return err(pos, "a second root element");
            }
            let start = pos + 1;
            let mut q = start;
            while q < b.len() && is_name_byte(b[q]) {
                q += 1;
            }
            if q == start {
                return err(pos, "`<` not followed by an element name");
            }
            let mut el = Element {
                name: &text[start..q],
                attrs: Vec::new(),
                children: Vec::new(),
                text: "",
                offset: pos,
                text_offset: q,
            };
            let closed;
            loop {
                while q < b.len() && b[q].is_ascii_whitespace() {
                    q += 1;
                }
                if q >= b.len() {
                    return err(pos, format!("unterminated start tag `<{}`", el.name));
                }
                if b[q] == b'>' {
                    q += 1;
                    closed = false;
                    break;
                }
                if text[q..].starts_with("/>") {
                    q += 2;
                    closed = true;
                    break;
                }
                let a0 = q;
                while q < b.len() && is_name_byte(b[q]) {
                    q += 1;
                }
                if a0 == q {
                    return err(q, format!("bad character in start tag `<{}`", el.name));
                }
                let key = &text[a0..q];
                while q < b.len() && b[q].is_ascii_whitespace() {
                    q += 1;
                }
                if q >= b.len() || b[q] != b'=' {
                    return err(q, format!("attribute `{key}` has no value"));
                }
                q += 1;
                while q < b.len() && b[q].is_ascii_whitespace() {
                    q += 1;
                }
                if q >= b.len() || (b[q] != b'"' && b[q] != b'\'') {
                    return err(q, format!("attribute `{key}`: value must be quoted"));
                }
                let quote = b[q] as char;
                let v0 = q + 1;
                let Some(v1) = text[v0..].find(quote).map(|p| v0 + p) else {
                    return err(q, format!("attribute `{key}`: unterminated value"));
                };
                el.attrs.push((key, unescape(&text[v0..v1], v0)?));
                q = v1 + 1;
            }
            el.text_offset = q;
            pos = q;
            if closed {
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => root = Some(el),
                }
            } else {
                stack.push(el);
            }
        }
    }
    if let Some(open) = stack.last() {
        return err(
            text.len(),
            format!("unexpected end of file: `<{}>` is not closed", open.name),
        );
    }
    root.ok_or(XmlError {
        offset: 0,
        what: "no root element".into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tree_text_attrs_lines() {
        let t = "<?xml version=\"1.0\"?>\n<!-- c -->\n<A x='1' y=\"a&amp;b\">\n <B>  12 3\n</B><C/>\n</A>\n";
        let r = parse(t).ok().unwrap();
        assert_eq!(r.name, "A");
        assert_eq!(r.attr("y"), Some("a&b"));
        assert_eq!(r.children.len(), 2);
        let bb = r.child("B").unwrap();
        assert_eq!(bb.text.trim(), "12 3");
        let li = LineIndex::new(t);
        assert_eq!(li.line(bb.offset), 4);
        assert_eq!(li.line(r.offset), 3);
        let e = parse("<A>\n<B>\n</A>").err().unwrap();
        assert_eq!(LineIndex::new("<A>\n<B>\n</A>").line(e.offset), 3);
        assert!(parse("<A>").is_err());
    }
}
