//! The one parser of `--method` (`detect`, `eval`, `tune`): `all` or one method name.

use tirroi_core::Method;

/// The help of a `--method` option: `what`, then every method of the core registry
/// (`Method::ALL`, so a new detector appears without editing any help text) and `all`.
pub fn method_help(what: &str) -> String {
    let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
    format!(
        "{what}: {}, or all (the {} in this order)",
        names.join(", "),
        names.len()
    )
}

/// One method or all of them.
#[derive(Debug, Clone)]
pub struct MethodChoice(pub Vec<Method>);

/// Parses `all` (every method, in `Method::ALL` order) or one method name.
///
/// # Errors
/// One line naming the accepted names.
pub fn parse_methods(s: &str) -> Result<MethodChoice, String> {
    if s == "all" {
        return Ok(MethodChoice(Method::ALL.to_vec()));
    }
    Method::from_name(s)
        .map(|m| MethodChoice(vec![m]))
        .ok_or_else(|| {
            let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
            format!("unknown method `{s}`; expected {} or all", names.join(", "))
        })
}
