//! The one parser of `--method` (`detect`, `eval`, `tune`): `all` or one method name.

use tirroi_core::Method;

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
