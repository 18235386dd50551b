//! A small preprocessor for the WGSL kernel template: `//#if FEATURE` … `//#else` … `//#endif`
//! blocks (nestable) are kept or dropped by feature, and `{{NAME}}` is replaced by a value.

use std::collections::HashMap;

/// Expands `template`: a line `//#if NAME` (or `//#if !NAME`) opens a block kept only when
/// the feature is on (off); `//#else` and `//#endif` close it. Directive lines and `//%`
/// comments (about the template itself) are dropped.
/// Returns an error naming the line of an unbalanced directive or an unknown placeholder.
pub fn expand(
    template: &str,
    features: &HashMap<&str, bool>,
    values: &HashMap<&str, String>,
) -> Result<String, String> {
    let mut out = String::with_capacity(template.len());
    // Each open block: (this branch is kept, the enclosing block is kept).
    let mut stack: Vec<(bool, bool)> = Vec::new();
    for (n, line) in template.lines().enumerate() {
        let trimmed = line.trim_start();
        let live = stack.last().is_none_or(|&(kept, outer)| kept && outer);
        if let Some(cond) = trimmed.strip_prefix("//#if ") {
            let cond = cond.trim();
            let (negate, name) = match cond.strip_prefix('!') {
                Some(name) => (true, name),
                None => (false, cond),
            };
            let on = *features
                .get(name)
                .ok_or_else(|| format!("line {}: unknown feature `{name}`", n + 1))?;
            stack.push((on != negate, live));
        } else if trimmed.starts_with("//#else") {
            let top = stack
                .last_mut()
                .ok_or_else(|| format!("line {}: `//#else` without `//#if`", n + 1))?;
            top.0 = !top.0;
        } else if trimmed.starts_with("//#endif") {
            stack
                .pop()
                .ok_or_else(|| format!("line {}: `//#endif` without `//#if`", n + 1))?;
        } else if live && !trimmed.starts_with("//%") {
            out.push_str(&substitute(line, values).map_err(|e| format!("line {}: {e}", n + 1))?);
            out.push('\n');
        }
    }
    if !stack.is_empty() {
        return Err("unclosed `//#if`".to_string());
    }
    Ok(out)
}

fn substitute(line: &str, values: &HashMap<&str, String>) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = line;
    while let Some(start) = rest.find("{{") {
        out.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        let end = after.find("}}").ok_or("unclosed `{{`")?;
        let name = &after[..end];
        out.push_str(
            values
                .get(name)
                .ok_or_else(|| format!("unknown placeholder `{name}`"))?,
        );
        rest = &after[end + 2..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_and_drops_blocks() {
        let features = HashMap::from([("A", true), ("B", false)]);
        let values = HashMap::from([("N", "3".to_string())]);
        let t = "x\n//#if A\na{{N}}\n//#if B\nb\n//#else\nnot b\n//#endif\n//#endif\n//#if !A\nnot a\n//#endif\n";
        assert_eq!(expand(t, &features, &values).unwrap(), "x\na3\nnot b\n");
        assert!(expand("//#if C\n//#endif\n", &features, &values).is_err());
        assert!(expand("//#if A\n", &features, &values).is_err());
        assert!(expand("{{M}}\n", &features, &values).is_err());
    }
}
