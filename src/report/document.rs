//! A report as a list of blocks, rendered both to Markdown (figures linked as SVG files) and to
//! an HTML page (plots inlined, large mesh pictures shown from their files).

/// One block of a report.
#[derive(Debug, Clone)]
pub enum Block {
    /// A heading of level 1..=4.
    Heading(u8, String),
    /// A paragraph of plain text.
    Para(String),
    /// A bulleted list of plain-text items.
    List(Vec<String>),
    /// A table: header cells and rows of cells (plain text).
    Table {
        /// Column titles.
        header: Vec<String>,
        /// Rows, each as many cells as the header.
        rows: Vec<Vec<String>>,
    },
    /// A figure: its SVG, the file name it is written to (relative to the report), a caption.
    Figure {
        /// File name of the SVG, relative to the report's directory.
        file: String,
        /// The SVG document.
        svg: String,
        /// Caption (plain text).
        caption: String,
    },
}

/// A report being built.
#[derive(Debug, Clone, Default)]
pub struct Document {
    /// The blocks, in order.
    pub blocks: Vec<Block>,
}

impl Document {
    /// Appends a heading.
    pub fn heading(&mut self, level: u8, text: impl Into<String>) {
        self.blocks.push(Block::Heading(level, text.into()));
    }

    /// Appends a paragraph.
    pub fn para(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Para(text.into()));
    }

    /// Appends a list (nothing when empty).
    pub fn list(&mut self, items: Vec<String>) {
        if !items.is_empty() {
            self.blocks.push(Block::List(items));
        }
    }

    /// Appends a table.
    pub fn table(&mut self, header: Vec<String>, rows: Vec<Vec<String>>) {
        self.blocks.push(Block::Table { header, rows });
    }

    /// Appends a figure. A file name already taken by another figure gets a `-2`, `-3`, ...
    /// before its extension, so that no figure overwrites another.
    pub fn figure(&mut self, file: String, svg: String, caption: String) {
        let taken = |f: &str| self.figures().any(|(g, _)| g == f);
        let mut unique = file.clone();
        let (stem, ext) = file.rsplit_once('.').unwrap_or((&file, ""));
        let mut k = 2;
        while taken(&unique) {
            unique = format!("{stem}-{k}.{ext}");
            k += 1;
        }
        self.blocks.push(Block::Figure {
            file: unique,
            svg,
            caption,
        });
    }

    /// The figures, as (file, svg).
    pub fn figures(&self) -> impl Iterator<Item = (&str, &str)> {
        self.blocks.iter().filter_map(|b| match b {
            Block::Figure { file, svg, .. } => Some((file.as_str(), svg.as_str())),
            _ => None,
        })
    }

    /// Markdown, with figures as image links to their files.
    pub fn to_markdown(&self) -> String {
        let mut out = String::new();
        for b in &self.blocks {
            match b {
                Block::Heading(level, text) => {
                    out.push_str(&"#".repeat(*level as usize));
                    out.push(' ');
                    out.push_str(&md_escape(text));
                    out.push_str("\n\n");
                }
                Block::Para(text) => {
                    out.push_str(&md_escape(text));
                    out.push_str("\n\n");
                }
                Block::List(items) => {
                    for i in items {
                        out.push_str("- ");
                        out.push_str(&md_escape(i));
                        out.push('\n');
                    }
                    out.push('\n');
                }
                Block::Table { header, rows } => {
                    let cell = |s: &str| md_escape(s);
                    out.push_str("| ");
                    out.push_str(
                        &header
                            .iter()
                            .map(|h| cell(h))
                            .collect::<Vec<_>>()
                            .join(" | "),
                    );
                    out.push_str(" |\n|");
                    for (i, _) in header.iter().enumerate() {
                        out.push_str(if i == 0 { " --- |" } else { " ---: |" });
                    }
                    out.push('\n');
                    for r in rows {
                        out.push_str("| ");
                        out.push_str(&r.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | "));
                        out.push_str(" |\n");
                    }
                    out.push('\n');
                }
                Block::Figure { file, caption, .. } => {
                    let alt = std::path::Path::new(file)
                        .file_stem()
                        .map_or(file.clone(), |s| s.to_string_lossy().into_owned());
                    out.push_str(&format!("![{}]({file})\n\n", md_escape(&alt)));
                    out.push_str(&format!("*{}*\n\n", md_escape(caption)));
                }
            }
        }
        out
    }

    /// An HTML page with the figures' SVG inlined, except those over [`INLINE_MAX`] bytes (mesh
    /// pictures), which it shows from their files under `figures/` beside it.
    pub fn to_html(&self, title: &str) -> String {
        let mut out = String::new();
        out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        out.push_str(&format!("<title>{}</title>\n", escape(title)));
        out.push_str(
            "<style>\nbody{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;\
             line-height:1.45}\ntable{border-collapse:collapse;margin:1em 0;font-size:0.92em}\n\
             th,td{border:1px solid #bbb;padding:0.25em 0.6em}td{text-align:right}\n\
             td:first-child{text-align:left}th{background:#eee}\nfigure{margin:1.5em 0}\n\
             figure svg{max-width:100%;height:auto}\nfigcaption{font-size:0.9em;color:#333}\n\
             </style>\n</head>\n<body>\n",
        );
        for b in &self.blocks {
            match b {
                Block::Heading(level, text) => {
                    out.push_str(&format!("<h{level}>{}</h{level}>\n", escape(text)));
                }
                Block::Para(text) => out.push_str(&format!("<p>{}</p>\n", escape(text))),
                Block::List(items) => {
                    out.push_str("<ul>\n");
                    for i in items {
                        out.push_str(&format!("<li>{}</li>\n", escape(i)));
                    }
                    out.push_str("</ul>\n");
                }
                Block::Table { header, rows } => {
                    out.push_str("<table>\n<thead><tr>");
                    for h in header {
                        out.push_str(&format!("<th>{}</th>", escape(h)));
                    }
                    out.push_str("</tr></thead>\n<tbody>\n");
                    for r in rows {
                        out.push_str("<tr>");
                        for c in r {
                            out.push_str(&format!("<td>{}</td>", escape(c)));
                        }
                        out.push_str("</tr>\n");
                    }
                    out.push_str("</tbody>\n</table>\n");
                }
                Block::Figure { file, svg, caption } if svg.len() > INLINE_MAX => {
                    // A large picture (a mesh of thousands of elements) stays in its file
                    // beside the page, so that the page itself loads at once.
                    out.push_str(&format!(
                        "<figure>\n<a href=\"{0}\"><img src=\"{0}\" loading=\"lazy\" \
                         style=\"max-width:100%;height:auto\" alt=\"{1}\"></a>\n\
                         <figcaption>{1} (Picture {0}, {2:.1} MB, linked rather than inlined.)\
                         </figcaption>\n</figure>\n",
                        escape(file),
                        escape(caption),
                        svg.len() as f64 / 1e6
                    ));
                }
                Block::Figure { svg, caption, .. } => {
                    out.push_str("<figure>\n");
                    out.push_str(strip_xml_declaration(svg));
                    out.push_str(&format!(
                        "\n<figcaption>{}</figcaption>\n</figure>\n",
                        escape(caption)
                    ));
                }
            }
        }
        out.push_str("</body>\n</html>\n");
        out
    }
}

/// The largest figure inlined in the HTML page, in bytes: box plots (tens of kB) are, mesh
/// pictures (megabytes) are linked.
pub const INLINE_MAX: usize = 256 * 1024;

/// Plain text as Markdown that shows it as it is: every character Markdown or HTML could
/// read as markup (emphasis, code, links, images, raw HTML, entities, table cells, headings)
/// is backslash-escaped, a leading list or heading marker too, and line breaks become
/// spaces. Mesh names and directories come from the user (`<img src=x onerror=...>` as a
/// mesh name was raw HTML in report.md).
pub fn md_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for (i, c) in s.chars().enumerate() {
        match c {
            '\\' | '`' | '*' | '_' | '{' | '}' | '[' | ']' | '<' | '>' | '#' | '|' | '!' | '~'
            | '&' => {
                out.push('\\');
                out.push(c);
            }
            '-' | '+' | '=' if i == 0 => {
                out.push('\\');
                out.push(c);
            }
            '\n' | '\r' => out.push(' '),
            _ => out.push(c),
        }
    }
    // "1. x" or "1) x" at the start is an ordered list ("85.1" is not).
    let digits = out.chars().take_while(char::is_ascii_digit).count();
    let mut after = out[digits..].chars();
    if digits > 0
        && matches!(after.next(), Some('.' | ')'))
        && after.next().is_none_or(|c| c == ' ' || c == '\t')
    {
        out.insert(digits, '\\');
    }
    out
}

/// The SVG without an XML declaration (not allowed inside HTML).
fn strip_xml_declaration(svg: &str) -> &str {
    let s = svg.trim_start();
    if s.starts_with("<?xml") {
        s.find("?>").map_or(s, |i| s[i + 2..].trim_start())
    } else {
        s
    }
}

/// HTML-escapes text.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_pictures_are_linked_and_plots_inlined() {
        let mut doc = Document::default();
        let svg = |n: usize| format!("<svg>{}</svg>", "<g/>".repeat(n));
        doc.figure("figures/plot.svg".into(), svg(10), "a plot".into());
        doc.figure("figures/mesh.svg".into(), svg(INLINE_MAX), "a mesh".into());
        let html = doc.to_html("t");
        assert_eq!(html.matches("<svg>").count(), 1);
        assert!(html.contains(r#"<img src="figures/mesh.svg""#), "{html}");
        assert!(html.len() < 4096, "{} bytes", html.len());
    }

    #[test]
    fn md_escape_leaves_no_markup() {
        assert_eq!(
            md_escape("<img src=x onerror=alert(2)>"),
            r"\<img src=x onerror=alert(2)\>"
        );
        assert_eq!(
            md_escape("a_b *c* [d](e) `f` | g"),
            r"a\_b \*c\* \[d\](e) \`f\` \| g"
        );
        assert_eq!(md_escape("# h"), r"\# h");
        assert_eq!(md_escape("- x"), r"\- x");
        assert_eq!(md_escape("1. x"), r"1\. x");
        assert_eq!(md_escape("85.1"), "85.1");
        assert_eq!(md_escape("a\nb\r\nc"), "a b  c");
        assert_eq!(
            md_escape("selective h=3 (30 runs)"),
            "selective h=3 (30 runs)"
        );
    }
}
