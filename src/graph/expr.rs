//! Size expressions of graph buffers: integer literals and count names joined by `*` and `+`
//! (`*` binds tighter), e.g. `"width * height"` or `"64 + 2 * width"`. Nothing else is accepted.

/// A term of a sum: the product of its factors.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Factor {
    Number(u64),
    Name(String),
}

/// A parsed expression: a sum of products.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Expr {
    pub(crate) terms: Vec<Vec<(Factor, usize)>>,
}

/// A parse or evaluation error with the byte offset in the expression text it is about.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ExprError {
    pub(crate) offset: usize,
    pub(crate) message: String,
}

fn err<T>(offset: usize, message: impl Into<String>) -> Result<T, ExprError> {
    Err(ExprError { offset, message: message.into() })
}

impl Expr {
    pub(crate) fn parse(text: &str) -> Result<Self, ExprError> {
        let bytes = text.as_bytes();
        let mut i = 0;
        let skip = |i: &mut usize| {
            while *i < bytes.len() && bytes[*i].is_ascii_whitespace() {
                *i += 1;
            }
        };
        let mut terms = vec![Vec::new()];
        loop {
            skip(&mut i);
            let start = i;
            if i < bytes.len() && bytes[i].is_ascii_digit() {
                while i < bytes.len() && bytes[i].is_ascii_digit() {
                    i += 1;
                }
                let n: u64 = text[start..i]
                    .parse()
                    .or_else(|_| err(start, format!("`{}` is too large", &text[start..i])))?;
                terms.last_mut().unwrap().push((Factor::Number(n), start));
            } else if i < bytes.len() && (bytes[i].is_ascii_alphabetic() || bytes[i] == b'_') {
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                terms.last_mut().unwrap().push((Factor::Name(text[start..i].to_string()), start));
            } else if i == bytes.len() {
                return err(start, "expected a number or a count name at the end of the expression");
            } else {
                let c = text[i..].chars().next().unwrap();
                return err(start, format!("expected a number or a count name, found `{c}`"));
            }
            skip(&mut i);
            match bytes.get(i) {
                None => break,
                Some(b'*') => i += 1,
                Some(b'+') => {
                    i += 1;
                    terms.push(Vec::new());
                }
                Some(_) => {
                    let c = text[i..].chars().next().unwrap();
                    return err(i, format!("expected `*`, `+` or the end of the expression, found `{c}`"));
                }
            }
        }
        Ok(Expr { terms })
    }

    /// Count names the expression uses, with their offsets.
    pub(crate) fn names(&self) -> impl Iterator<Item = (&str, usize)> {
        self.terms.iter().flatten().filter_map(|(f, at)| match f {
            Factor::Name(n) => Some((n.as_str(), *at)),
            Factor::Number(_) => None,
        })
    }

    /// The value, names looked up in `count` (which reports an unknown one); an overflow of 64
    /// bits is an error at the start of the expression.
    pub(crate) fn eval(&self, count: impl Fn(&str) -> Option<u64>) -> Result<u64, ExprError> {
        let mut sum: u64 = 0;
        for term in &self.terms {
            let mut product: u64 = 1;
            for (f, at) in term {
                let v = match f {
                    Factor::Number(n) => *n,
                    Factor::Name(n) => match count(n) {
                        Some(v) => v,
                        None => return err(*at, format!("unknown count `{n}`")),
                    },
                };
                product = product.checked_mul(v).map_or_else(|| err(0, "the size overflows 64 bits"), Ok)?;
            }
            sum = sum.checked_add(product).map_or_else(|| err(0, "the size overflows 64 bits"), Ok)?;
        }
        Ok(sum)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(text: &str) -> Result<u64, ExprError> {
        Expr::parse(text)?.eval(|n| match n {
            "width" => Some(64),
            "height" => Some(32),
            _ => None,
        })
    }

    #[test]
    fn precedence_and_names() {
        assert_eq!(value("256"), Ok(256));
        assert_eq!(value("width * height"), Ok(2048));
        assert_eq!(value(" 4 + 2*width*height + 1 "), Ok(4101));
    }

    #[test]
    fn rejects_anything_else() {
        assert_eq!(value("width - 1").unwrap_err().offset, 6);
        assert_eq!(value("(width)").unwrap_err().offset, 0);
        assert_eq!(value("width *").unwrap_err().offset, 7);
        assert_eq!(value("").unwrap_err().offset, 0);
        assert_eq!(
            value("2 * depth").unwrap_err(),
            ExprError { offset: 4, message: "unknown count `depth`".into() }
        );
        assert!(value("99999999999 * 99999999999").unwrap_err().message.contains("overflows"));
        assert!(value("width 2").unwrap_err().message.contains("expected `*`"));
    }
}
