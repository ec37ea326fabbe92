//! The syntax tree of a Structured Text file, as written (names keep their spelling; the
//! checker resolves them, ASCII case ignored).

use crate::diag::Pos;

/// A name and where it stands.
#[derive(Debug, Clone, PartialEq)]
pub struct Name {
    /// As written.
    pub text: String,
    /// Its first character.
    pub pos: Pos,
}

impl Name {
    /// Whether it is `other`, ASCII case ignored.
    pub fn is(&self, other: &str) -> bool {
        self.text.eq_ignore_ascii_case(other)
    }
}

/// One source file: its declarations in order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Unit {
    /// Programs, function blocks, functions, type blocks and global variable lists.
    pub items: Vec<Item>,
}

/// A top-level declaration.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// PROGRAM, FUNCTION_BLOCK or FUNCTION.
    Pou(Pou),
    /// `TYPE .. END_TYPE`.
    Types(Vec<TypeDecl>),
    /// A global variable list (`VAR_GLOBAL .. END_VAR` outside a POU).
    Globals(VarBlock),
}

/// The kind of a program organisation unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PouKind {
    /// PROGRAM.
    Program,
    /// FUNCTION_BLOCK.
    FunctionBlock,
    /// FUNCTION (with its return type).
    Function,
    /// A METHOD or ACTION of a FUNCTION_BLOCK or PROGRAM, as the checker makes it a POU of
    /// its own (`check::methods`); never written as such.
    Method,
}

/// A program, function block or function.
#[derive(Debug, Clone, PartialEq)]
pub struct Pou {
    /// Which kind.
    pub kind: PouKind,
    /// Its name.
    pub name: Name,
    /// A function's return type.
    pub returns: Option<TypeRef>,
    /// Its variable sections in order.
    pub vars: Vec<VarBlock>,
    /// Its statements.
    pub body: Vec<Stmt>,
    /// Its methods and actions (of a FUNCTION_BLOCK or a PROGRAM).
    pub methods: Vec<Method>,
}

/// A METHOD or an ACTION of a function block or a program: a body run on the instance
/// (the program), with the method's own variables and value.
#[derive(Debug, Clone, PartialEq)]
pub struct Method {
    /// Its name.
    pub name: Name,
    /// An ACTION (no variables of its own, no value).
    pub action: bool,
    /// PRIVATE or PROTECTED: called only from its POU's body and methods.
    pub private: bool,
    /// Its value's type.
    pub returns: Option<TypeRef>,
    /// Its own variable sections.
    pub vars: Vec<VarBlock>,
    /// Its statements.
    pub body: Vec<Stmt>,
}

/// Which section a variable is declared in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Section {
    /// VAR.
    Var,
    /// VAR_INPUT.
    Input,
    /// VAR_OUTPUT.
    Output,
    /// VAR_IN_OUT.
    InOut,
    /// VAR_GLOBAL.
    Global,
    /// VAR_TEMP.
    Temp,
    /// VAR_EXTERNAL.
    External,
}

/// `VAR_x [CONSTANT] [RETAIN|PERSISTENT] .. END_VAR`.
#[derive(Debug, Clone, PartialEq)]
pub struct VarBlock {
    /// The section.
    pub section: Section,
    /// CONSTANT.
    pub constant: bool,
    /// RETAIN or PERSISTENT (kept as a mark; the PLC keeps no memory across restarts).
    pub retain: bool,
    /// The declarations.
    pub vars: Vec<VarDecl>,
    /// Where the section starts.
    pub pos: Pos,
}

/// `a, b : TYPE := init;`.
#[derive(Debug, Clone, PartialEq)]
pub struct VarDecl {
    /// The names declared.
    pub names: Vec<Name>,
    /// Their type.
    pub ty: TypeRef,
    /// Their initial value.
    pub init: Option<Init>,
}

/// A type as a declaration writes it.
#[derive(Debug, Clone, PartialEq)]
pub enum TypeRef {
    /// An elementary, declared or function block type by name.
    Named(Name),
    /// `ARRAY[lo..hi, ..] OF T`.
    Array {
        /// The bounds of each dimension.
        ranges: Vec<(Expr, Expr)>,
        /// The element type.
        element: Box<TypeRef>,
        /// `ARRAY`.
        pos: Pos,
    },
    /// `POINTER TO T`.
    Pointer(Box<TypeRef>, Pos),
    /// `REFERENCE TO T`.
    Reference(Box<TypeRef>, Pos),
    /// `STRING` or `STRING(n)` (`WSTRING` with `wide`).
    String {
        /// The length in characters, if given.
        len: Option<Box<Expr>>,
        /// WSTRING.
        wide: bool,
        /// `STRING`.
        pos: Pos,
    },
}

/// An initial value.
#[derive(Debug, Clone, PartialEq)]
pub enum Init {
    /// An expression.
    Expr(Expr),
    /// `[a, b, n(c)]`: elements, `n(c)` repeats `c` n times.
    Array(Vec<(Option<Expr>, Init)>),
    /// `(field := value, ..)`.
    Struct(Vec<(Name, Init)>),
}

/// `Name : definition;` in a TYPE block.
#[derive(Debug, Clone, PartialEq)]
pub struct TypeDecl {
    /// The type's name.
    pub name: Name,
    /// What it is.
    pub def: TypeDef,
}

/// A declared type.
#[derive(Debug, Clone, PartialEq)]
pub enum TypeDef {
    /// `STRUCT .. END_STRUCT`.
    Struct(Vec<VarDecl>),
    /// `UNION .. END_UNION`: fields that share their bytes.
    Union(Vec<VarDecl>),
    /// `(A, B := 5, C) [INT]`: the values, each with its number if given, and the base type.
    Enum {
        /// The values.
        values: Vec<(Name, Option<Expr>)>,
        /// The base type, if given.
        base: Option<TypeRef>,
    },
    /// Another type under this name, with an initial value if given.
    Alias(TypeRef, Option<Init>),
}

/// A statement.
#[derive(Debug, Clone, PartialEq)]
pub enum Stmt {
    /// `target := value;`.
    Assign {
        /// A variable, field, element or dereference.
        target: Expr,
        /// The value.
        value: Expr,
    },
    /// A call as a statement: a function block instance or a function.
    Call(Expr),
    /// IF .. ELSIF .. ELSE .. END_IF.
    If {
        /// Each condition with its statements.
        branches: Vec<(Expr, Vec<Stmt>)>,
        /// ELSE.
        otherwise: Option<Vec<Stmt>>,
    },
    /// CASE .. OF .. ELSE .. END_CASE.
    Case {
        /// The selector.
        selector: Expr,
        /// Each arm's labels and statements.
        arms: Vec<(Vec<CaseLabel>, Vec<Stmt>)>,
        /// ELSE.
        otherwise: Option<Vec<Stmt>>,
    },
    /// FOR i := a TO b [BY c] DO .. END_FOR.
    For {
        /// The control variable.
        var: Name,
        /// The first value.
        from: Expr,
        /// The last value.
        to: Expr,
        /// The step (1 if not given).
        by: Option<Expr>,
        /// The statements.
        body: Vec<Stmt>,
    },
    /// WHILE c DO .. END_WHILE.
    While {
        /// The condition.
        cond: Expr,
        /// The statements.
        body: Vec<Stmt>,
    },
    /// REPEAT .. UNTIL c END_REPEAT.
    Repeat {
        /// The statements.
        body: Vec<Stmt>,
        /// The condition that ends it.
        until: Expr,
    },
    /// EXIT (the innermost loop).
    Exit(Pos),
    /// CONTINUE (the innermost loop's next round).
    Continue(Pos),
    /// RETURN.
    Return(Pos),
}

/// A CASE label.
#[derive(Debug, Clone, PartialEq)]
pub enum CaseLabel {
    /// One value.
    Value(Expr),
    /// `lo..hi`.
    Range(Expr, Expr),
}

/// A unary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnOp {
    /// `-`.
    Neg,
    /// NOT.
    Not,
}

/// A binary operator, lowest precedence first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// OR.
    Or,
    /// XOR.
    Xor,
    /// AND, `&`.
    And,
    /// `=`.
    Eq,
    /// `<>`.
    Ne,
    /// `<`.
    Lt,
    /// `>`.
    Gt,
    /// `<=`.
    Le,
    /// `>=`.
    Ge,
    /// `+`.
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
    /// MOD.
    Mod,
    /// `**`.
    Pow,
    /// AND_THEN (TwinCAT, CODESYS): AND of BOOLs whose right value is computed only when the
    /// left is TRUE (`p <> 0 AND_THEN p^.bReady`).
    AndThen,
    /// OR_ELSE: OR of BOOLs whose right value is computed only when the left is FALSE.
    OrElse,
}

/// An argument of a call.
#[derive(Debug, Clone, PartialEq)]
pub enum Arg {
    /// By position.
    Positional(Expr),
    /// `Name := value`.
    Input(Name, Expr),
    /// `Name => target` (`NOT Name => target` with `negated`).
    Output {
        /// The output.
        name: Name,
        /// Where it goes.
        target: Expr,
        /// Its negation goes.
        negated: bool,
    },
}

/// An expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// An integer literal.
    Int(i128, Pos),
    /// A real literal.
    Real(f64, Pos),
    /// TRUE or FALSE.
    Bool(bool, Pos),
    /// A string literal.
    Str(String, Pos),
    /// A duration, in nanoseconds; an LTIME's (`LTIME#..`) with `true`.
    Time(i128, bool, Pos),
    /// A typed literal: `DINT#-5`, `E_Mode#Run`.
    Typed {
        /// The type prefix.
        ty: Name,
        /// The literal (a number, a string, TRUE/FALSE or an enum value's name).
        value: Box<Expr>,
    },
    /// A variable, constant, enum value, POU or type by name.
    Name(Name),
    /// `base.field`.
    Field(Box<Expr>, Name),
    /// `base[i, j]`.
    Index(Box<Expr>, Vec<Expr>, Pos),
    /// `base^`.
    Deref(Box<Expr>, Pos),
    /// `callee(args)`.
    Call {
        /// A function, a function block instance or a standard function.
        callee: Box<Expr>,
        /// The arguments.
        args: Vec<Arg>,
        /// The `(`.
        pos: Pos,
    },
    /// A unary operation.
    Unary(UnOp, Box<Expr>, Pos),
    /// A binary operation.
    Binary(BinOp, Box<Expr>, Box<Expr>, Pos),
}

impl Expr {
    /// Where it starts.
    pub fn pos(&self) -> Pos {
        match self {
            Expr::Int(_, p)
            | Expr::Real(_, p)
            | Expr::Bool(_, p)
            | Expr::Str(_, p)
            | Expr::Time(_, _, p)
            | Expr::Unary(_, _, p) => *p,
            Expr::Typed { ty, .. } => ty.pos,
            Expr::Name(n) => n.pos,
            Expr::Field(base, _)
            | Expr::Index(base, _, _)
            | Expr::Deref(base, _)
            | Expr::Call { callee: base, .. }
            | Expr::Binary(_, base, _, _) => base.pos(),
        }
    }
}
