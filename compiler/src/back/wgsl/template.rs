//! A small preprocessor for the WGSL kernel template: `//#if FEATURE` … `//#else` … `//#endif`
//! blocks (nestable) are kept or dropped by feature, and `{{NAME}}` is replaced by a value.

use std::collections::HashMap;

/// What is wrong with the template, at its `line` (1-based) where there is one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TemplateError {
    #[error("line {line}: unknown feature `{name}`")]
    UnknownFeature { line: usize, name: String },
    #[error("line {line}: `//#else` without `//#if`")]
    StrayElse { line: usize },
    #[error("line {line}: `//#endif` without `//#if`")]
    StrayEndif { line: usize },
    #[error("unclosed `//#if`")]
    Unclosed,
    #[error("line {line}: unclosed `{{{{`")]
    UnclosedPlaceholder { line: usize },
    #[error("line {line}: unknown placeholder `{name}`")]
    UnknownPlaceholder { line: usize, name: String },
}

/// Expands `template`: a line `//#if NAME` (or `//#if !NAME`) opens a block kept only when
/// the feature is on (off); `//#else` and `//#endif` close it. Directive lines and `//%`
/// comments (about the template itself) are dropped.
/// Returns an error naming the line of an unbalanced directive or an unknown placeholder.
pub fn expand(
    template: &str,
    features: &HashMap<&str, bool>,
    values: &HashMap<&str, String>,
) -> Result<String, TemplateError> {
    let mut out = String::with_capacity(template.len());
    // Each open block: (this branch is kept, the enclosing block is kept).
    let mut stack: Vec<(bool, bool)> = Vec::new();
    for (n, line) in template.lines().enumerate() {
        let trimmed = line.trim_start();
        let n = n + 1;
        let live = stack.last().is_none_or(|&(kept, outer)| kept && outer);
        if let Some(cond) = trimmed.strip_prefix("//#if ") {
            let cond = cond.trim();
            let (negate, name) = match cond.strip_prefix('!') {
                Some(name) => (true, name),
                None => (false, cond),
            };
            let on = *features
                .get(name)
                .ok_or_else(|| TemplateError::UnknownFeature {
                    line: n,
                    name: name.into(),
                })?;
            stack.push((on != negate, live));
        } else if trimmed.starts_with("//#else") {
            let top = stack
                .last_mut()
                .ok_or(TemplateError::StrayElse { line: n })?;
            top.0 = !top.0;
        } else if trimmed.starts_with("//#endif") {
            stack.pop().ok_or(TemplateError::StrayEndif { line: n })?;
        } else if live && !trimmed.starts_with("//%") {
            out.push_str(&substitute(line, n, values)?);
            out.push('\n');
        }
    }
    if !stack.is_empty() {
        return Err(TemplateError::Unclosed);
    }
    Ok(out)
}

/// `line` (the `n`th) with its placeholders replaced.
fn substitute(
    line: &str,
    n: usize,
    values: &HashMap<&str, String>,
) -> Result<String, TemplateError> {
    let mut out = String::new();
    let mut rest = line;
    while let Some(start) = rest.find("{{") {
        out.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        let end = after
            .find("}}")
            .ok_or(TemplateError::UnclosedPlaceholder { line: n })?;
        let name = &after[..end];
        out.push_str(
            values
                .get(name)
                .ok_or_else(|| TemplateError::UnknownPlaceholder {
                    line: n,
                    name: name.into(),
                })?,
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
        let fails = |t| expand(t, &features, &values).unwrap_err();
        assert_eq!(
            fails("//#if C\n//#endif\n"),
            TemplateError::UnknownFeature {
                line: 1,
                name: "C".into()
            }
        );
        assert_eq!(fails("//#if A\n"), TemplateError::Unclosed);
        assert_eq!(fails("x\n//#else\n"), TemplateError::StrayElse { line: 2 });
        assert_eq!(
            fails("{{M}}\n"),
            TemplateError::UnknownPlaceholder {
                line: 1,
                name: "M".into()
            }
        );
        assert_eq!(
            fails("a {{M\n"),
            TemplateError::UnclosedPlaceholder { line: 1 }
        );
        assert_eq!(fails("a {{M\n").to_string(), "line 1: unclosed `{{`");
    }
}
