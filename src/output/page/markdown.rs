//! The markdown the reports write, as HTML: headings, paragraphs, bullet lists, pipe tables,
//! fenced code, and inline `code`, **bold**, *emphasis* and [links](url). Every character of the
//! text is escaped; only the markup this module emits is HTML. Links keep relative targets and
//! http(s) ones; any other scheme (javascript:, data:) is dropped and the text kept.

use super::escape;

/// The report's markdown as an HTML fragment.
pub fn to_html(md: &str) -> String {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let t = line.trim_start();
        if t.starts_with("```") {
            let end = lines[i + 1..]
                .iter()
                .position(|l| l.trim_start().starts_with("```"))
                .map_or(lines.len(), |k| i + 1 + k);
            out += "<pre><code>";
            for l in &lines[i + 1..end] {
                out += &escape(l);
                out.push('\n');
            }
            out += "</code></pre>\n";
            i = end + 1;
        } else if let Some((level, text)) = heading(t) {
            out += &format!("<h{level}>{}</h{level}>\n", inline(text));
            i += 1;
        } else if t.starts_with('|') {
            let end = run(&lines, i, |l| l.trim_start().starts_with('|'));
            out += &table(&lines[i..end]);
            i = end;
        } else if bullet(t).is_some() {
            let end = run(&lines, i, |l| {
                bullet(l.trim_start()).is_some() || l.starts_with("  ") && !l.trim().is_empty()
            });
            out += "<ul>\n";
            let mut item = String::new();
            for l in &lines[i..end] {
                if let Some(text) = bullet(l.trim_start()) {
                    if !item.is_empty() {
                        out += &format!("<li>{}</li>\n", inline(&item));
                    }
                    item = text.to_string();
                } else {
                    item = format!("{item} {}", l.trim());
                }
            }
            out += &format!("<li>{}</li>\n</ul>\n", inline(&item));
            i = end;
        } else if t.is_empty() {
            i += 1;
        } else {
            let end = run(&lines, i, |l| {
                let t = l.trim_start();
                !t.is_empty()
                    && !t.starts_with('|')
                    && !t.starts_with("```")
                    && heading(t).is_none()
                    && bullet(t).is_none()
            });
            let text: Vec<&str> = lines[i..end].iter().map(|l| l.trim()).collect();
            out += &format!("<p>{}</p>\n", inline(&text.join(" ")));
            i = end.max(i + 1);
        }
    }
    out
}

/// The end of the run of lines from `start` that satisfy `keep`.
fn run(lines: &[&str], start: usize, keep: impl Fn(&str) -> bool) -> usize {
    lines[start..]
        .iter()
        .position(|l| !keep(l))
        .map_or(lines.len(), |k| start + k)
}

fn heading(t: &str) -> Option<(usize, &str)> {
    let level = t.bytes().take_while(|&b| b == b'#').count();
    (1..=6)
        .contains(&level)
        .then(|| t[level..].strip_prefix(' '))
        .flatten()
        .map(|text| (level, text))
}

fn bullet(t: &str) -> Option<&str> {
    t.strip_prefix("- ").or_else(|| t.strip_prefix("* "))
}

fn cells(line: &str) -> Vec<&str> {
    let t = line.trim();
    let t = t.strip_prefix('|').unwrap_or(t);
    let t = t.strip_suffix('|').unwrap_or(t);
    t.split('|').map(str::trim).collect()
}

fn table(lines: &[&str]) -> String {
    let separator = |l: &str| {
        cells(l)
            .iter()
            .all(|c| !c.is_empty() && c.chars().all(|ch| matches!(ch, '-' | ':')))
    };
    let mut out = String::from("<table class=\"report\">\n");
    let (head, body) = match lines.get(1) {
        Some(l) if separator(l) => (Some(lines[0]), &lines[2..]),
        _ => (None, lines),
    };
    if let Some(h) = head {
        out += "<thead><tr>";
        for c in cells(h) {
            out += &format!("<th>{}</th>", inline(c));
        }
        out += "</tr></thead>\n";
    }
    out += "<tbody>\n";
    for l in body {
        out += "<tr>";
        for c in cells(l) {
            out += &format!("<td>{}</td>", inline(c));
        }
        out += "</tr>\n";
    }
    out + "</tbody></table>\n"
}

/// Inline markup of one block's text.
fn inline(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix('`') {
            if let Some(end) = r.find('`') {
                out += &format!("<code>{}</code>", escape(&r[..end]));
                rest = &r[end + 1..];
                continue;
            }
        }
        if let Some(r) = rest.strip_prefix("**") {
            if let Some(end) = r.find("**") {
                out += &format!("<strong>{}</strong>", inline(&r[..end]));
                rest = &r[end + 2..];
                continue;
            }
        }
        if let Some(r) = rest.strip_prefix('*') {
            if let Some(end) = r.find('*').filter(|&e| e > 0 && !r.starts_with(' ')) {
                out += &format!("<em>{}</em>", inline(&r[..end]));
                rest = &r[end + 1..];
                continue;
            }
        }
        if let Some(r) = rest.strip_prefix('[') {
            if let Some((label, target, after)) = link(r) {
                if safe_target(target) {
                    out += &format!("<a href=\"{}\">{}</a>", escape(target), inline(label));
                } else {
                    out += &inline(label);
                }
                rest = after;
                continue;
            }
        }
        let c = rest.chars().next().expect("non-empty");
        out += &escape(&c.to_string());
        rest = &rest[c.len_utf8()..];
    }
    out
}

/// `label](target)rest` split at its brackets.
fn link(r: &str) -> Option<(&str, &str, &str)> {
    let close = r.find("](")?;
    let end = r[close + 2..].find(')')? + close + 2;
    Some((&r[..close], &r[close + 2..end], &r[end + 1..]))
}

fn safe_target(target: &str) -> bool {
    let lower = target.trim().to_ascii_lowercase();
    match lower.find(':') {
        Some(colon) if !lower[..colon].contains('/') => lower.starts_with("http://") || lower.starts_with("https://"),
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reports_markup_becomes_html() {
        let md = "# Title <x>\n\nA `a<b` **bold** and *it*.\nsecond line\n\n- one\n- two `c`\n  continued\n\n| a | b |\n|---|---|\n| 1 | <2> |\n\n```\nx < y\n```\n";
        assert_eq!(
            to_html(md),
            "<h1>Title &lt;x&gt;</h1>\n<p>A <code>a&lt;b</code> <strong>bold</strong> and <em>it</em>. second line</p>\n\
             <ul>\n<li>one</li>\n<li>two <code>c</code> continued</li>\n</ul>\n\
             <table class=\"report\">\n<thead><tr><th>a</th><th>b</th></tr></thead>\n<tbody>\n<tr><td>1</td><td>&lt;2&gt;</td></tr>\n</tbody></table>\n\
             <pre><code>x &lt; y\n</code></pre>\n"
        );
    }

    #[test]
    fn hostile_text_stays_text() {
        let html = to_html("[x](javascript:alert(1)) [y](plots/a.svg) [z](https://e.org) <script>alert(1)</script> \"q\" * 2 * 3 ** ``");
        assert!(!html.contains("<script"), "{html}");
        assert!(!html.contains("javascript:"), "{html}");
        assert!(html.contains("<a href=\"plots/a.svg\">y</a>"), "{html}");
        assert!(html.contains("<a href=\"https://e.org\">z</a>"), "{html}");
        assert!(html.contains("&lt;script&gt;"), "{html}");
        assert!(html.contains("&quot;q&quot;"), "{html}");
        // An unclosed fence runs to the end and is still escaped.
        assert_eq!(to_html("```\n<b>"), "<pre><code>&lt;b&gt;\n</code></pre>\n");
    }
}
