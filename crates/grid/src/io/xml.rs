//! The element tree of a VTK XML file, read with `quick-xml`: elements, attributes (with
//! entities and character references replaced) and the text directly inside each element.
//! Comments, the `<?xml?>` declaration, processing instructions and `<!DOCTYPE>` are
//! skipped. Text is borrowed from the document, so large ASCII or base64 arrays are not
//! copied.

use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;

/// One XML element.
#[derive(Debug)]
pub(crate) struct Element<'a> {
    pub name: &'a str,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element<'a>>,
    /// The text directly inside the element (from the end of the start tag to the first
    /// child, comment or end tag).
    pub text: &'a str,
    /// Byte offset of the start tag and of `text`.
    pub offset: usize,
    pub text_offset: usize,
}

impl<'a> Element<'a> {
    pub(crate) fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
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
    /// This element and all its descendants, depth first.
    pub(crate) fn walk(&self, f: &mut impl FnMut(&Element<'a>)) {
        f(self);
        for c in &self.children {
            c.walk(f);
        }
    }
}

/// Maps byte offsets to 1-based line numbers.
pub(crate) struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub(crate) fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(memchr::memchr_iter(b'\n', text.as_bytes()).map(|i| i + 1));
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

/// The element of a start (or empty-element) tag that begins at byte `at` and ends before
/// byte `end`.
fn element<'a>(
    text: &'a str,
    at: usize,
    end: usize,
    tag: &BytesStart<'_>,
) -> Result<Element<'a>, XmlError> {
    // The raw tag is `<` followed by the name.
    let n = tag.name().as_ref().len();
    let name = text.get(at + 1..at + 1 + n).unwrap_or_default();
    let mut attrs = Vec::new();
    for a in tag.attributes() {
        let bad = |e: &dyn std::fmt::Display| XmlError {
            offset: at,
            what: format!("in start tag `<{name}`: {e}"),
        };
        let a = a.map_err(|e| bad(&e))?;
        let key = std::str::from_utf8(a.key.as_ref()).map_err(|e| bad(&e))?;
        let value = a
            .normalized_value(XmlVersion::Implicit1_0)
            .map_err(|e| bad(&e))?;
        attrs.push((key.to_string(), value.into_owned()));
    }
    Ok(Element {
        name,
        attrs,
        children: Vec::new(),
        text: "",
        offset: at,
        text_offset: end,
    })
}

/// Parse a document and return its root element.
pub(crate) fn parse(text: &str) -> Result<Element<'_>, XmlError> {
    let mut reader = Reader::from_str(text);
    let mut stack: Vec<Element<'_>> = Vec::new();
    let mut root: Option<Element<'_>> = None;
    loop {
        let at = reader.buffer_position() as usize;
        let event = match reader.read_event() {
            Ok(e) => e,
            Err(e) => return err(reader.error_position() as usize, e.to_string()),
        };
        let end = reader.buffer_position() as usize;
        match event {
            Event::Start(_) | Event::Empty(_) if stack.is_empty() && root.is_some() => {
                return err(at, "a second root element");
            }
            Event::Start(tag) => stack.push(element(text, at, end, &tag)?),
            Event::Empty(tag) => {
                let el = element(text, at, end, &tag)?;
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::End(_) => {
                // quick-xml checks that the names match.
                let Some(el) = stack.pop() else {
                    return err(at, "end tag without a start tag");
                };
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::Text(_) | Event::GeneralRef(_) | Event::CData(_) => match stack.last_mut() {
                Some(top) => {
                    if top.children.is_empty() && top.text.is_empty() {
                        top.text = text.get(at..end).unwrap_or_default();
                        top.text_offset = at;
                    }
                }
                None => {
                    if !text.get(at..end).unwrap_or_default().trim().is_empty() {
                        return err(at, "text outside the root element");
                    }
                }
            },
            Event::Eof => break,
            Event::Comment(_) | Event::Decl(_) | Event::PI(_) | Event::DocType(_) => {}
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
        let t = "<?xml version=\"1.0\"?>\n<!-- c -->\n<A x='1' y=\"a&amp;b&#x41;\">\n <B>  12 3\n</B><C/>\n</A>\n";
        let r = parse(t).ok().unwrap();
        assert_eq!(r.name, "A");
        assert_eq!(r.attr("x"), Some("1"));
        assert_eq!(r.attr("y"), Some("a&bA"));
        assert_eq!(r.children.len(), 2);
        let bb = r.child("B").unwrap();
        assert_eq!(bb.text.trim(), "12 3");
        assert_eq!(&t[bb.text_offset..bb.text_offset + 4], "  12");
        assert!(r.child("C").unwrap().children.is_empty());
        let li = LineIndex::new(t);
        assert_eq!(li.line(bb.offset), 4);
        assert_eq!(li.line(r.offset), 3);
        let e = parse("<A>\n<B>\n</A>").err().unwrap();
        assert_eq!(LineIndex::new("<A>\n<B>\n</A>").line(e.offset), 3);
        assert!(parse("<A>").is_err());
        assert!(parse("<A/><B/>").is_err());
        assert!(parse("<A/>x").is_err());
        assert!(parse("<A x=1/>").is_err());
    }
}
