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
//! once into a small stack program and then evaluated without allocation. `sin` and `cos`
//! are those of [`super::trig`] (within one unit in the last place of the correctly
//! rounded values, and vectorized over the lanes of a batch).

use std::fmt;

use super::trig;

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
    /// [`Func::apply`] on every lane, the function chosen once.
    fn apply_lanes(self, a: &[f64; LANES]) -> [f64; LANES] {
        match self {
            Func::Sin => trig::sin_lanes(a),
            Func::Cos => trig::cos_lanes(a),
            Func::Tan => lanes1(a, f64::tan),
            Func::Exp => lanes1(a, f64::exp),
            Func::Ln => lanes1(a, f64::ln),
            Func::Sqrt => lanes1(a, f64::sqrt),
            Func::Abs => lanes1(a, f64::abs),
        }
    }

    fn apply(self, v: f64) -> f64 {
        match self {
            Func::Sin => trig::sin(v),
            Func::Cos => trig::cos(v),
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
    /// `a^2` as `a·a` (the common power, exact to rounding).
    Square,
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
            ops: fold_constants(p.ops),
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

    /// The constant `v` as an expression.
    pub fn constant(v: f64) -> Self {
        Self {
            ops: vec![Op::Num(v)],
            text: format!("{v}"),
        }
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
                Op::Square => stack[sp - 1] *= stack[sp - 1],
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

/// Points evaluated together by [`Program::eval_points`].
pub const LANES: usize = 32;

/// Several expressions compiled into one program that evaluates every common
/// subexpression once (the components of a body force share `sin(pi*x)`, ...).
///
/// Each expression's stack program becomes nodes of a DAG: a node is an operation on
/// earlier nodes, and identical operations on identical operands are one node. The
/// nodes are evaluated in order into a scratch array; every node computes exactly what
/// [`Expr::eval`] computes for that subexpression, so the values are the same bit for bit.
#[derive(Clone, Debug)]
pub struct Program {
    nodes: Vec<Node>,
    /// Arguments of `min`/`max` nodes.
    args: Vec<u32>,
    outputs: Vec<u32>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Node {
    Num(f64),
    Var(usize),
    Neg(u32),
    Square(u32),
    Call1(Func, u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Pow(u32, u32),
    /// `a + c`, `a − c`, `c − a`, `a · c`, `a / c`, `c / a` with a constant `c`: the
    /// same operations as with a constant node, without loading it.
    AddC(u32, f64),
    SubC(u32, f64),
    CSub(f64, u32),
    MulC(u32, f64),
    DivC(u32, f64),
    CDiv(f64, u32),
    /// `min`/`max` over `args[start..start + len]`.
    Min(u32, u32),
    Max(u32, u32),
    /// `sin a` into the first node given and `cos a` into the second, in one `sin_cos`
    /// call, at the first of the two.
    SinCos(u32, u32, u32),
    /// A value a [`Node::SinCos`] before it wrote.
    Written,
}

impl Program {
    /// Compile `exprs` together (output `i` is `exprs[i]`).
    pub fn new(exprs: &[&Expr]) -> Self {
        let mut p = Self {
            nodes: Vec::new(),
            args: Vec::new(),
            outputs: Vec::new(),
        };
        let mut index: std::collections::HashMap<NodeKey, u32> = std::collections::HashMap::new();
        for e in exprs {
            let mut stack: Vec<u32> = Vec::new();
            for op in &e.ops {
                let node = match *op {
                    Op::Num(v) => Node::Num(v),
                    Op::Var(k) => Node::Var(k),
                    Op::Neg => Node::Neg(stack.pop().unwrap_or(0)),
                    Op::Square => Node::Square(stack.pop().unwrap_or(0)),
                    Op::Call1(f) => Node::Call1(f, stack.pop().unwrap_or(0)),
                    Op::Min(n) | Op::Max(n) => {
                        let from = stack.len().saturating_sub(n);
                        let start = p.args.len() as u32;
                        p.args.extend(stack.drain(from..));
                        if matches!(op, Op::Min(_)) {
                            Node::Min(start, n as u32)
                        } else {
                            Node::Max(start, n as u32)
                        }
                    }
                    Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow => {
                        let b = stack.pop().unwrap_or(0);
                        let a = stack.pop().unwrap_or(0);
                        let num = |k: u32| match p.nodes[k as usize] {
                            Node::Num(c) => Some(c),
                            _ => None,
                        };
                        match (op, num(a), num(b)) {
                            (Op::Add, _, Some(c)) => Node::AddC(a, c),
                            (Op::Add, Some(c), _) => Node::AddC(b, c),
                            (Op::Sub, _, Some(c)) => Node::SubC(a, c),
                            (Op::Sub, Some(c), _) => Node::CSub(c, b),
                            (Op::Mul, _, Some(c)) => Node::MulC(a, c),
                            (Op::Mul, Some(c), _) => Node::MulC(b, c),
                            (Op::Div, _, Some(c)) => Node::DivC(a, c),
                            (Op::Div, Some(c), _) => Node::CDiv(c, b),
                            (Op::Add, ..) => Node::Add(a, b),
                            (Op::Sub, ..) => Node::Sub(a, b),
                            (Op::Mul, ..) => Node::Mul(a, b),
                            (Op::Div, ..) => Node::Div(a, b),
                            _ => Node::Pow(a, b),
                        }
                    }
                };
                let key = NodeKey::of(&node, &p.args);
                let id = *index.entry(key).or_insert_with(|| {
                    p.nodes.push(node);
                    (p.nodes.len() - 1) as u32
                });
                stack.push(id);
            }
            p.outputs.push(stack.pop().unwrap_or(0));
        }
        p.drop_unused();
        p.pair_sin_cos();
        p
    }

    /// The operands of a node.
    fn operands(&self, node: &Node) -> Vec<u32> {
        match *node {
            Node::Num(_) | Node::Var(_) | Node::Written => vec![],
            Node::SinCos(a, ..) => vec![a],
            Node::Neg(a)
            | Node::Square(a)
            | Node::Call1(_, a)
            | Node::AddC(a, _)
            | Node::SubC(a, _)
            | Node::CSub(_, a)
            | Node::MulC(a, _)
            | Node::DivC(a, _)
            | Node::CDiv(_, a) => vec![a],
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Pow(a, b) => vec![a, b],
            Node::Min(s, n) | Node::Max(s, n) => self.args[s as usize..(s + n) as usize].to_vec(),
        }
    }

    /// Remove the nodes no output needs (constants fused into their operations) and
    /// renumber the rest, keeping their order.
    fn drop_unused(&mut self) {
        let mut used = vec![false; self.nodes.len()];
        for &o in &self.outputs {
            used[o as usize] = true;
        }
        for i in (0..self.nodes.len()).rev() {
            if used[i] {
                for k in self.operands(&self.nodes[i]) {
                    used[k as usize] = true;
                }
            }
        }
        let mut new_id = vec![0u32; self.nodes.len()];
        let mut nodes = Vec::with_capacity(self.nodes.len());
        for (i, node) in self.nodes.iter().enumerate() {
            if used[i] {
                new_id[i] = nodes.len() as u32;
                nodes.push(*node);
            }
        }
        let map = |k: u32| new_id[k as usize];
        for node in &mut nodes {
            *node = match *node {
                Node::Neg(a) => Node::Neg(map(a)),
                Node::Square(a) => Node::Square(map(a)),
                Node::Call1(f, a) => Node::Call1(f, map(a)),
                Node::AddC(a, c) => Node::AddC(map(a), c),
                Node::SubC(a, c) => Node::SubC(map(a), c),
                Node::CSub(c, a) => Node::CSub(c, map(a)),
                Node::MulC(a, c) => Node::MulC(map(a), c),
                Node::DivC(a, c) => Node::DivC(map(a), c),
                Node::CDiv(c, a) => Node::CDiv(c, map(a)),
                Node::Add(a, b) => Node::Add(map(a), map(b)),
                Node::Sub(a, b) => Node::Sub(map(a), map(b)),
                Node::Mul(a, b) => Node::Mul(map(a), map(b)),
                Node::Div(a, b) => Node::Div(map(a), map(b)),
                Node::Pow(a, b) => Node::Pow(map(a), map(b)),
                other => other,
            };
        }
        for a in &mut self.args {
            *a = map(*a);
        }
        for o in &mut self.outputs {
            *o = map(*o);
        }
        self.nodes = nodes;
    }

    /// Where a program takes both `sin a` and `cos a` (a manufactured load's `sin(pi*x)`
    /// and `cos(pi*x)`), compute them in one `sin_cos` call at the first of the two
    /// nodes: the argument reduction is shared, which makes the pair about as cheap as
    /// one. [`trig::sin_cos`] gives the same values as [`trig::sin`] and [`trig::cos`].
    fn pair_sin_cos(&mut self) {
        let mut first: std::collections::HashMap<u32, (Option<usize>, Option<usize>)> =
            std::collections::HashMap::new();
        for (i, node) in self.nodes.iter().enumerate() {
            if let Node::Call1(f @ (Func::Sin | Func::Cos), a) = *node {
                let e = first.entry(a).or_default();
                let slot = if f == Func::Sin { &mut e.0 } else { &mut e.1 };
                slot.get_or_insert(i);
            }
        }
        for (a, pair) in first {
            if let (Some(si), Some(ci)) = pair {
                self.nodes[si.min(ci)] = Node::SinCos(a, si as u32, ci as u32);
                self.nodes[si.max(ci)] = Node::Written;
            }
        }
    }

    /// Number of distinct operations.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the program computes nothing.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Evaluate every output at `x` (missing coordinates count as 0) and time `t`.
    pub fn eval(&self, x: &[f64], t: f64, out: &mut [f64]) {
        // One scratch array per thread, grown once (every node is written before it is
        // read, so it needs no clearing).
        thread_local! {
            static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        SCRATCH.with(|cell| match cell.try_borrow_mut() {
            Ok(mut v) => {
                if v.len() < self.nodes.len() {
                    v.resize(self.nodes.len(), 0.0);
                }
                self.eval_with(x, t, &mut v, out);
            }
            // Re-entered on this thread (a program evaluated inside another's caller).
            Err(_) => self.eval_with(x, t, &mut vec![0.0; self.nodes.len()], out),
        });
    }

    /// Evaluate every output at each point of `xs` and time `t`: `out` holds
    /// `xs.len() × len(outputs)` values, point after point. The points go through the
    /// program [`LANES`] at a time, each operation over all lanes in one loop, so the
    /// interpretation costs once per lane group instead of once per point; every lane
    /// computes exactly what [`Program::eval`] computes, bit for bit.
    pub fn eval_points<const D: usize>(&self, xs: &[[f64; D]], t: f64, out: &mut [f64]) {
        let m = self.outputs.len();
        assert_eq!(out.len(), xs.len() * m, "eval_points: output length");
        thread_local! {
            static LANE_SCRATCH: std::cell::RefCell<Vec<[f64; LANES]>> =
                const { std::cell::RefCell::new(Vec::new()) };
        }
        let mut run = |v: &mut [[f64; LANES]]| {
            for (pts, vals) in xs.chunks(LANES).zip(out.chunks_mut(LANES * m)) {
                self.eval_lanes(pts, t, v);
                for (p, row) in vals.chunks_mut(m).enumerate() {
                    for (o, &k) in row.iter_mut().zip(&self.outputs) {
                        *o = v[k as usize][p];
                    }
                }
            }
        };
        LANE_SCRATCH.with(|cell| match cell.try_borrow_mut() {
            Ok(mut v) => {
                if v.len() < self.nodes.len() {
                    v.resize(self.nodes.len(), [0.0; LANES]);
                }
                run(&mut v)
            }
            Err(_) => run(&mut vec![[0.0; LANES]; self.nodes.len()]),
        });
    }

    /// Every node at up to [`LANES`] points (lanes past `pts.len()` repeat the last point).
    fn eval_lanes<const D: usize>(&self, pts: &[[f64; D]], t: f64, v: &mut [[f64; LANES]]) {
        let coord = |k: usize| -> [f64; LANES] {
            std::array::from_fn(|l| {
                let p = &pts[l.min(pts.len() - 1)];
                if k == 3 {
                    t
                } else {
                    p.get(k).copied().unwrap_or(0.0)
                }
            })
        };
        for (i, node) in self.nodes.iter().enumerate() {
            // Operands are earlier nodes: split so they can be read while `i` is written.
            let (done, rest) = v.split_at_mut(i);
            let g = |k: u32| &done[k as usize];
            rest[0] = match *node {
                Node::SinCos(a, si, ci) => {
                    let (sin, cos) = trig::sin_cos_lanes(g(a));
                    let later = si.max(ci) as usize - i;
                    (rest[0], rest[later]) = if si < ci { (sin, cos) } else { (cos, sin) };
                    continue;
                }
                Node::Written => continue,
                Node::Num(c) => [c; LANES],
                Node::Var(k) => coord(k),
                Node::Neg(a) => lanes1(g(a), |a| -a),
                Node::Square(a) => lanes1(g(a), |a| a * a),
                Node::Call1(f, a) => f.apply_lanes(g(a)),
                Node::Add(a, b) => lanes2(g(a), g(b), |a, b| a + b),
                Node::Sub(a, b) => lanes2(g(a), g(b), |a, b| a - b),
                Node::Mul(a, b) => lanes2(g(a), g(b), |a, b| a * b),
                Node::Div(a, b) => lanes2(g(a), g(b), |a, b| a / b),
                Node::Pow(a, b) => lanes2(g(a), g(b), f64::powf),
                Node::AddC(a, c) => lanes1(g(a), |a| a + c),
                Node::SubC(a, c) => lanes1(g(a), |a| a - c),
                Node::CSub(c, a) => lanes1(g(a), |a| c - a),
                Node::MulC(a, c) => lanes1(g(a), |a| a * c),
                Node::DivC(a, c) => lanes1(g(a), |a| a / c),
                Node::CDiv(c, a) => lanes1(g(a), |a| c / a),
                Node::Min(s, n) | Node::Max(s, n) => {
                    let min = matches!(node, Node::Min(..));
                    let mut acc = [if min {
                        f64::INFINITY
                    } else {
                        f64::NEG_INFINITY
                    }; LANES];
                    for &k in &self.args[s as usize..(s + n) as usize] {
                        let a = g(k);
                        for l in 0..LANES {
                            acc[l] = if min {
                                acc[l].min(a[l])
                            } else {
                                acc[l].max(a[l])
                            };
                        }
                    }
                    acc
                }
            };
        }
    }

    fn eval_with(&self, x: &[f64], t: f64, v: &mut [f64], out: &mut [f64]) {
        for (i, node) in self.nodes.iter().enumerate() {
            let g = |k: u32| v[k as usize];
            let value = match *node {
                Node::SinCos(a, si, ci) => {
                    let (sin, cos) = trig::sin_cos(g(a));
                    v[si as usize] = sin;
                    v[ci as usize] = cos;
                    continue;
                }
                Node::Written => continue,
                Node::Num(c) => c,
                Node::Var(3) => t,
                Node::Var(k) => x.get(k).copied().unwrap_or(0.0),
                Node::Neg(a) => -g(a),
                Node::Square(a) => g(a) * g(a),
                Node::Call1(f, a) => f.apply(g(a)),
                Node::Add(a, b) => g(a) + g(b),
                Node::Sub(a, b) => g(a) - g(b),
                Node::Mul(a, b) => g(a) * g(b),
                Node::Div(a, b) => g(a) / g(b),
                Node::Pow(a, b) => g(a).powf(g(b)),
                Node::AddC(a, c) => g(a) + c,
                Node::SubC(a, c) => g(a) - c,
                Node::CSub(c, a) => c - g(a),
                Node::MulC(a, c) => g(a) * c,
                Node::DivC(a, c) => g(a) / c,
                Node::CDiv(c, a) => c / g(a),
                Node::Min(s, n) => self.args[s as usize..(s + n) as usize]
                    .iter()
                    .map(|&k| g(k))
                    .fold(f64::INFINITY, f64::min),
                Node::Max(s, n) => self.args[s as usize..(s + n) as usize]
                    .iter()
                    .map(|&k| g(k))
                    .fold(f64::NEG_INFINITY, f64::max),
            };
            v[i] = value;
        }
        for (o, &k) in out.iter_mut().zip(&self.outputs) {
            *o = v[k as usize];
        }
    }
}

/// `f` applied lane by lane (generic, so it inlines into a loop the compiler vectorizes).
#[inline(always)]
fn lanes1(a: &[f64; LANES], f: impl Fn(f64) -> f64) -> [f64; LANES] {
    std::array::from_fn(|l| f(a[l]))
}

/// `f` applied lane by lane to two operands.
#[inline(always)]
fn lanes2(a: &[f64; LANES], b: &[f64; LANES], f: impl Fn(f64, f64) -> f64) -> [f64; LANES] {
    std::array::from_fn(|l| f(a[l], b[l]))
}

/// Identity of a node for common-subexpression elimination (constants by their bits).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum NodeKey {
    Num(u64),
    Var(usize),
    Un(u8, u32),
    Bin(u8, u32, u32),
    Const(u8, u32, u64),
    Many(bool, Vec<u32>),
}

impl NodeKey {
    fn of(node: &Node, args: &[u32]) -> Self {
        match *node {
            Node::Num(c) => Self::Num(c.to_bits()),
            Node::Var(k) => Self::Var(k),
            Node::Neg(a) => Self::Un(0, a),
            Node::Square(a) => Self::Un(1, a),
            Node::Call1(f, a) => Self::Un(2 + f as u8, a),
            Node::Add(a, b) => Self::Bin(0, a, b),
            Node::Sub(a, b) => Self::Bin(1, a, b),
            Node::Mul(a, b) => Self::Bin(2, a, b),
            Node::Div(a, b) => Self::Bin(3, a, b),
            Node::Pow(a, b) => Self::Bin(4, a, b),
            Node::AddC(a, c) => Self::Const(0, a, c.to_bits()),
            Node::SubC(a, c) => Self::Const(1, a, c.to_bits()),
            Node::CSub(c, a) => Self::Const(2, a, c.to_bits()),
            Node::MulC(a, c) => Self::Const(3, a, c.to_bits()),
            Node::DivC(a, c) => Self::Const(4, a, c.to_bits()),
            Node::CDiv(c, a) => Self::Const(5, a, c.to_bits()),
            Node::SinCos(a, si, ci) => Self::Const(6, a, (u64::from(si) << 32) | u64::from(ci)),
            Node::Written => Self::Num(u64::MAX),
            Node::Min(s, n) | Node::Max(s, n) => Self::Many(
                matches!(node, Node::Min(..)),
                args[s as usize..(s + n) as usize].to_vec(),
            ),
        }
    }
}

/// Fold every operation whose operands are all constants into one constant (`9*pi^2`
/// becomes one number), and `a^2` into [`Op::Square`]. The folded constants are computed
/// by the same arithmetic as [`Expr::eval`], so values do not change; this only removes
/// work from every evaluation.
fn fold_constants(ops: Vec<Op>) -> Vec<Op> {
    let mut out: Vec<Op> = Vec::with_capacity(ops.len());
    // Whether each entry of the evaluation stack is a constant (then it is one `Num` op at
    // the end of `out`, since constants are folded as soon as they appear).
    let mut constant: Vec<bool> = Vec::new();
    for op in ops {
        let arity = match op {
            Op::Num(_) | Op::Var(_) => 0,
            Op::Neg | Op::Call1(_) | Op::Square => 1,
            Op::Min(n) | Op::Max(n) => n,
            Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow => 2,
        };
        if op == Op::Pow && out.last() == Some(&Op::Num(2.0)) && constant.last() == Some(&true) {
            // a^2 → a·a (folded below if a is a constant too).
            out.pop();
            constant.pop();
            return_square(&mut out, &mut constant);
            continue;
        }
        let all_constant = arity > 0 && constant[constant.len() - arity..].iter().all(|&c| c);
        out.push(op);
        if all_constant {
            let start = out.len() - 1 - arity;
            let value = Expr {
                ops: out[start..].to_vec(),
                text: String::new(),
            }
            .eval(&[], 0.0);
            out.truncate(start);
            out.push(Op::Num(value));
            constant.truncate(constant.len() - arity);
            constant.push(true);
        } else {
            let n = constant.len() - arity;
            constant.truncate(n);
            constant.push(matches!(op, Op::Num(_)));
        }
    }
    out
}

/// Apply [`Op::Square`] to the top of the stack, folding it if that is a constant.
fn return_square(out: &mut Vec<Op>, constant: &mut [bool]) {
    match (out.last().copied(), constant.last()) {
        (Some(Op::Num(v)), Some(true)) => {
            out.pop();
            out.push(Op::Num(v * v));
        }
        _ => {
            out.push(Op::Square);
            if let Some(c) = constant.last_mut() {
                *c = false;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(s: &str, x: &[f64], t: f64) -> f64 {
        Expr::parse(s).unwrap().eval(x, t)
    }

    #[test]
    fn programs_share_subexpressions_and_give_the_same_values() {
        let texts = [
            "-x*z/52 + pi*y*sin(pi*x)/104 + 11*pi^2*sin(pi*x)*sin(pi*y)*sin(pi*z)/520",
            "-y*z/130 - pi^2*sin(pi*z)*cos(pi*x)*cos(pi*y)/104 - cos(pi*x)/104",
            "-x^2/104 + pi^2*y*z*cos(pi*x)/260 - pi^2*sin(pi*y)*cos(pi*x)*cos(pi*z)/104",
            "min(x, y, 0.5) + max(t, z)^2",
        ];
        let exprs: Vec<Expr> = texts.iter().map(|t| Expr::parse(t).unwrap()).collect();
        let refs: Vec<&Expr> = exprs.iter().collect();
        let p = Program::new(&refs);
        let pairs = p
            .nodes
            .iter()
            .filter(|n| matches!(n, Node::SinCos(..)))
            .count();
        let single = p
            .nodes
            .iter()
            .filter(|n| matches!(n, Node::Call1(..)))
            .count();
        assert_eq!(
            (pairs, single),
            (3, 0),
            "sin and cos of pi x, pi y, pi z, once each, in pairs"
        );
        // Constants are fused into their operations: no constant node is left but the
        // `0.5` argument of `min`.
        let nums = p.nodes.iter().filter(|n| matches!(n, Node::Num(_))).count();
        assert_eq!(nums, 1);
        let mut out = [0.0; 4];
        for (x, t) in [([0.1, 0.7, 0.3], 0.0), ([0.9, 0.2, 0.55], 1.5)] {
            p.eval(&x, t, &mut out);
            for (e, v) in exprs.iter().zip(out) {
                assert_eq!(e.eval(&x, t).to_bits(), v.to_bits());
            }
        }
    }

    /// Points evaluated together, in lane groups with a partial last group, give every
    /// expression's own value bit for bit, including `sin` and `cos` taken in one call
    /// (over arguments from 0 to far outside a period, where argument reduction matters).
    #[test]
    fn batched_points_give_the_same_values_bit_for_bit() {
        let texts = [
            "sin(pi*x)*cos(pi*y) + cos(pi*x) - sin(3*z)^2 + x^2*y",
            "cos(x*y*1e3) + sin(x*y*1e3) + exp(-z) + tan(y) + sqrt(abs(x - z))",
            "min(x, y, 0.5) + max(t, z)^2 - ln(1 + x) / (1 + y^2)",
            "x - 2*y^0.5 + 3 / (1 + z) + 1e6*sin(1e6*x)*cos(1e6*x)",
        ];
        let exprs: Vec<Expr> = texts.iter().map(|t| Expr::parse(t).unwrap()).collect();
        let refs: Vec<&Expr> = exprs.iter().collect();
        let p = Program::new(&refs);
        for n in [1, 7, 8, 9, 61] {
            let xs: Vec<[f64; 3]> = (0..n)
                .map(|i| {
                    let s = i as f64 + 0.5;
                    [0.37 * s, (1.3 * s).sin().abs(), 0.11 * s * s]
                })
                .collect();
            let t = 0.25;
            let mut out = vec![0.0; n * texts.len()];
            p.eval_points(&xs, t, &mut out);
            for (x, row) in xs.iter().zip(out.chunks(texts.len())) {
                for (e, v) in exprs.iter().zip(row) {
                    assert_eq!(e.eval(x, t).to_bits(), v.to_bits(), "{} at {x:?}", e.text());
                }
            }
        }
    }

    #[test]
    fn constants_are_folded_without_changing_values() {
        let text = "-x/52 + 9*pi^2*sin(pi*x)*sin(pi*y)/520";
        let e = Expr::parse(text).unwrap();
        // 9*pi^2 and pi are single numbers; x/52 stays.
        assert_eq!(e.ops.iter().filter(|o| matches!(o, Op::Num(_))).count(), 5);
        assert!(!e.ops.iter().any(|o| matches!(o, Op::Pow)));
        let (x, y) = (0.3, 0.7);
        let pi = std::f64::consts::PI;
        // The same operations in the same order (sin as the expressions take it).
        let want = -x / 52.0 + 9.0 * (pi * pi) * trig::sin(pi * x) * trig::sin(pi * y) / 520.0;
        assert_eq!(e.eval(&[x, y], 0.0), want);
        assert_eq!(ev("x^2 + 2^3 - max(1, 2, x)", &[3.0], 0.0), 9.0 + 8.0 - 3.0);
        assert_eq!(ev("(1 + 2)^2 * t", &[], 2.0), 18.0);
        assert_eq!(Expr::parse("2^2^3").unwrap().as_constant(), Some(256.0));
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
