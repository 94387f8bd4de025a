//! Space- and time-dependent scalar expressions of scene files.
//!
//! Grammar (usual precedence, `^` right-associative and binding tighter than unary minus,
//! so `-x^2 = -(x^2)`):
//!
//! ```text
//! expr    := term (('+' | '-') term)*
//! term    := unary (('*' | '/') unary)*
//! unary   := ('-' | '+') unary | power
//! power   := atom ('^' unary)?
//! atom    := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//! ```
//!
//! Variables `x, y, z` (m) and `t` (s); constants `pi`, `e`; functions `sin cos tan exp
//! ln sqrt abs` (one argument) and `min max` (two or more). An expression is compiled
//! once into a small stack program and then evaluated without allocation.

use std::fmt;

/// A compiled expression.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    ops: Vec<Op>,
    text: String,
}

const STACK: usize = 64;

/// Deepest nesting the parser accepts (parentheses, function arguments, signs and powers
/// together); deeper text is an error, never a stack overflow.
pub const MAX_NESTING: usize = 100;

/// One-argument functions.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Func {
    Sin,
    Cos,
    Tan,
    Exp,
    Ln,
    Sqrt,
    Abs,
}

impl Func {
    fn apply(self, v: f64) -> f64 {
        match self {
            Func::Sin => v.sin(),
            Func::Cos => v.cos(),
            Func::Tan => v.tan(),
            Func::Exp => v.exp(),
            Func::Ln => v.ln(),
            Func::Sqrt => v.sqrt(),
            Func::Abs => v.abs(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Num(f64),
    Var(usize), // 0..3 = x, y, z; 3 = t
    Neg,
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Call1(Func),
    Min(usize),
    Max(usize),
}

/// A syntax error with the character position (1-based) where it was found.
#[derive(Clone, Debug, PartialEq)]
pub struct ExprError {
    /// 1-based character column in the expression.
    pub column: usize,
    /// What is wrong.
    pub what: String,
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "column {}: {}", self.column, self.what)
    }
}

impl std::error::Error for ExprError {}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Sym(char),
}

fn tokenize(s: &str) -> Result<Vec<(Tok, usize)>, ExprError> {
    let chars: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // exponent: 1e-3, 2.5E+4
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text: String = chars[start..i].iter().collect();
            let v: f64 = text.parse().map_err(|_| ExprError {
                column: start + 1,
                what: format!("bad number `{text}`"),
            })?;
            out.push((Tok::Num(v), start + 1));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((Tok::Name(chars[start..i].iter().collect()), start + 1));
        } else if "+-*/^(),".contains(c) {
            out.push((Tok::Sym(c), i + 1));
            i += 1;
        } else {
            return Err(ExprError {
                column: i + 1,
                what: format!("unexpected character `{c}`"),
            });
        }
    }
    Ok(out)
}

struct Parser {
    toks: Vec<(Tok, usize)>,
    pos: usize,
    end: usize,
    ops: Vec<Op>,
    /// Current nesting depth (see [`MAX_NESTING`]).
    depth: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos).map(|t| &t.0)
    }
    fn column(&self) -> usize {
        self.toks.get(self.pos).map_or(self.end, |t| t.1)
    }
    fn err<T>(&self, what: impl Into<String>) -> Result<T, ExprError> {
        Err(ExprError {
            column: self.column(),
            what: what.into(),
        })
    }
    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(&Tok::Sym(c)) {
            self.pos += 1;
            true
        } else {
            false
        }
    }
    fn expr(&mut self) -> Result<(), ExprError> {
        self.term()?;
        loop {
            if self.eat('+') {
                self.term()?;
                self.ops.push(Op::Add);
            } else if self.eat('-') {
                self.term()?;
                self.ops.push(Op::Sub);
            } else {
                return Ok(());
            }
        }
    }
    fn term(&mut self) -> Result<(), ExprError> {
        self.unary()?;
        loop {
            if self.eat('*') {
                self.unary()?;
                self.ops.push(Op::Mul);
            } else if self.eat('/') {
                self.unary()?;
                self.ops.push(Op::Div);
            } else {
                return Ok(());
            }
        }
    }
    /// Every nesting (parentheses, arguments, unary signs, powers) passes through here,
    /// so the depth guard here bounds the recursion of the whole parser.
    fn unary(&mut self) -> Result<(), ExprError> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return self.err(format!(
                "the expression nests more than {MAX_NESTING} levels deep"
            ));
        }
        let result = if self.eat('-') {
            self.unary().map(|()| self.ops.push(Op::Neg))
        } else if self.eat('+') {
            self.unary()
        } else {
            self.power()
        };
        self.depth -= 1;
        result
    }
    fn power(&mut self) -> Result<(), ExprError> {
        self.atom()?;
        if self.eat('^') {
            self.unary()?;
            self.ops.push(Op::Pow);
        }
        Ok(())
    }
    fn atom(&mut self) -> Result<(), ExprError> {
        let col = self.column();
        match self.peek().cloned() {
            Some(Tok::Num(v)) => {
                self.pos += 1;
                self.ops.push(Op::Num(v));
                Ok(())
            }
            Some(Tok::Sym('(')) => {
                self.pos += 1;
                self.expr()?;
                if !self.eat(')') {
                    return self.err("expected `)`");
                }
                Ok(())
            }
            Some(Tok::Name(name)) => {
                self.pos += 1;
                if self.eat('(') {
                    let mut args = 0;
                    loop {
                        self.expr()?;
                        args += 1;
                        if self.eat(')') {
                            break;
                        }
                        if !self.eat(',') {
                            return self.err("expected `,` or `)`");
                        }
                    }
                    let f1 = match name.as_str() {
                        "sin" => Some(Func::Sin),
                        "cos" => Some(Func::Cos),
                        "tan" => Some(Func::Tan),
                        "exp" => Some(Func::Exp),
                        "ln" => Some(Func::Ln),
                        "sqrt" => Some(Func::Sqrt),
                        "abs" => Some(Func::Abs),
                        _ => None,
                    };
                    let bad_args = |want: &str| ExprError {
                        column: col,
                        what: format!("`{name}` takes {want} argument(s), got {args}"),
                    };
                    match (f1, name.as_str()) {
                        (Some(f), _) => {
                            if args != 1 {
                                return Err(bad_args("1"));
                            }
                            self.ops.push(Op::Call1(f));
                        }
                        (None, "min" | "max") => {
                            if args < 2 {
                                return Err(bad_args("2 or more"));
                            }
                            self.ops.push(if name == "min" {
                                Op::Min(args)
                            } else {
                                Op::Max(args)
                            });
                        }
                        _ => {
                            return Err(ExprError {
                                column: col,
                                what: format!(
                                    "unknown function `{name}` (known: sin cos tan exp ln sqrt abs min max)"
                                ),
                            });
                        }
                    }
                    return Ok(());
                }
                let op = match name.as_str() {
                    "x" => Op::Var(0),
                    "y" => Op::Var(1),
                    "z" => Op::Var(2),
                    "t" => Op::Var(3),
                    "pi" => Op::Num(std::f64::consts::PI),
                    "e" => Op::Num(std::f64::consts::E),
                    _ => {
                        return Err(ExprError {
                            column: col,
                            what: format!("unknown name `{name}` (known: x y z t pi e)"),
                        });
                    }
                };
                self.ops.push(op);
                Ok(())
            }
            Some(Tok::Sym(c)) => self.err(format!("unexpected `{c}`")),
            None => self.err("unexpected end of expression"),
        }
    }
}

impl Expr {
    /// Compile an expression.
    pub fn parse(text: &str) -> Result<Self, ExprError> {
        let toks = tokenize(text)?;
        let mut p = Parser {
            toks,
            pos: 0,
            end: text.chars().count() + 1,
            ops: Vec::new(),
            depth: 0,
        };
        p.expr()?;
        if p.pos != p.toks.len() {
            return p.err("unexpected text after the expression");
        }
        // The evaluator uses a fixed stack; reject expressions that would need more.
        let mut depth: usize = 0;
        for op in &p.ops {
            depth = match op {
                Op::Num(_) | Op::Var(_) => depth + 1,
                Op::Neg | Op::Call1(_) => depth,
                Op::Min(n) | Op::Max(n) => depth + 1 - n,
                _ => depth - 1,
            };
            if depth > STACK {
                return Err(ExprError {
                    column: 1,
                    what: format!("expression nests more than {STACK} levels deep"),
                });
            }
        }
        Ok(Self {
            ops: p.ops,
            text: text.to_string(),
        })
    }

    /// The source text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Whether the expression depends on time.
    pub fn depends_on_time(&self) -> bool {
        self.ops.contains(&Op::Var(3))
    }

    /// The value if the expression is a constant.
    pub fn as_constant(&self) -> Option<f64> {
        if self.ops.iter().any(|o| matches!(o, Op::Var(_))) {
            None
        } else {
            Some(self.eval(&[], 0.0))
        }
    }

    /// Evaluate at the point `x` (missing coordinates count as 0) and time `t`.
    pub fn eval(&self, x: &[f64], t: f64) -> f64 {
        let mut stack = [0.0f64; STACK];
        let mut sp = 0usize;
        for op in &self.ops {
            match *op {
                Op::Num(v) => {
                    stack[sp] = v;
                    sp += 1;
                }
                Op::Var(k) => {
                    stack[sp] = if k == 3 {
                        t
                    } else {
                        x.get(k).copied().unwrap_or(0.0)
                    };
                    sp += 1;
                }
                Op::Neg => stack[sp - 1] = -stack[sp - 1],
                Op::Call1(f) => stack[sp - 1] = f.apply(stack[sp - 1]),
                Op::Min(n) | Op::Max(n) => {
                    let args = &stack[sp - n..sp];
                    let v = if matches!(op, Op::Min(_)) {
                        args.iter().copied().fold(f64::INFINITY, f64::min)
                    } else {
                        args.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                    };
                    sp -= n - 1;
                    stack[sp - 1] = v;
                }
                Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow => {
                    let b = stack[sp - 1];
                    let a = stack[sp - 2];
                    sp -= 1;
                    stack[sp - 1] = match op {
                        Op::Add => a + b,
                        Op::Sub => a - b,
                        Op::Mul => a * b,
                        Op::Div => a / b,
                        _ => a.powf(b),
                    };
                }
            }
        }
        stack[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(s: &str, x: &[f64], t: f64) -> f64 {
        Expr::parse(s).unwrap().eval(x, t)
    }

    #[test]
    fn hostile_nesting_is_an_error_not_a_stack_overflow() {
        for text in [
            format!("{}x{}", "(".repeat(100_000), ")".repeat(100_000)),
            format!("{}x", "-".repeat(100_000)),
            format!("{}x{}", "sin(".repeat(100_000), ")".repeat(100_000)),
            vec!["x"; 100_000].join("^"),
        ] {
            let e = Expr::parse(&text).unwrap_err();
            assert!(e.what.contains("nests more than 100"), "{}", e.what);
        }
        // 40 levels are fine and evaluate correctly.
        let e = Expr::parse(&format!("{}x{}", "(".repeat(40), ")".repeat(40))).unwrap();
        assert_eq!(e.eval(&[2.5, 0.0, 0.0], 0.0), 2.5);
    }

    #[test]
    fn arithmetic_and_precedence() {
        assert_eq!(ev("1 + 2 * 3", &[], 0.0), 7.0);
        assert_eq!(ev("(1 + 2) * 3", &[], 0.0), 9.0);
        assert_eq!(ev("2 ^ 3 ^ 2", &[], 0.0), 512.0);
        assert_eq!(ev("-2 ^ 2", &[], 0.0), -4.0);
        assert_eq!(ev("2 ^ -1", &[], 0.0), 0.5);
        assert_eq!(ev("8 / 4 / 2", &[], 0.0), 1.0);
        assert_eq!(
            ev("1e-3*x + 2e-4*y", &[2.0, 5.0], 0.0),
            1e-3 * 2.0 + 2e-4 * 5.0
        );
        assert_eq!(ev("-1e6*min(t/60, 1)", &[], 30.0), -0.5e6);
        assert_eq!(ev("-1e6*min(t/60, 1)", &[], 120.0), -1e6);
        assert_eq!(ev("max(x, y, z, 0.5)", &[0.1, 0.2, 0.3], 0.0), 0.5);
        let v = ev("sin(pi*x)*sin(pi*y)/100", &[0.25, 0.5], 0.0);
        assert!((v - (std::f64::consts::PI * 0.25).sin() / 100.0).abs() < 1e-16);
        assert!(
            (ev(
                "ln(e) + sqrt(4) + abs(-3) + exp(0) + cos(0) + tan(0)",
                &[],
                0.0
            ) - 8.0)
                .abs()
                < 1e-15
        );
    }

    #[test]
    fn constants_and_time() {
        assert_eq!(
            Expr::parse("2*pi").unwrap().as_constant(),
            Some(2.0 * std::f64::consts::PI)
        );
        assert_eq!(Expr::parse("x").unwrap().as_constant(), None);
        assert!(Expr::parse("x*t").unwrap().depends_on_time());
        assert!(!Expr::parse("x*y").unwrap().depends_on_time());
    }

    #[test]
    fn errors_name_the_column() {
        let e = Expr::parse("1 + sinn(x)").unwrap_err();
        assert_eq!(e.column, 5);
        assert!(e.what.contains("sinn"));
        assert_eq!(Expr::parse("1 + ").unwrap_err().column, 5);
        assert_eq!(Expr::parse("(1 + 2").unwrap_err().column, 7);
        assert_eq!(Expr::parse("x $ 2").unwrap_err().column, 3);
        assert_eq!(Expr::parse("w + 1").unwrap_err().column, 1);
        assert!(Expr::parse("sin(1, 2)").is_err());
        assert!(Expr::parse("min(1)").is_err());
        assert!(Expr::parse("1 2").is_err());
    }
}
