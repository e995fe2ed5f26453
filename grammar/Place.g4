// Place.g4 - the .place robot language (docs/language.md is the reference).
// SPEL+ flavour: case-insensitive keywords, ' comments, one statement per line.
// Generated into the build tree at build time; frontend/parse.cpp is the only
// code that sees the generated types.
grammar Place;

// ---------------------------------------------------------------- structure
// A line is the unit of error recovery: each line is its own rule ending in
// its NEWLINE, so a mistake anywhere in a line is caught inside that line and
// never abandons the block around it. Every line ends in NEWLINE:
// frontend/parse.cpp adds one after a last line that lacks it. (Allowing
// "topLevel? EOF" would make ANTLR look ahead through a whole Function to
// choose between the two ways to end a line.)
program     : programLine* EOF ;
programLine : topLevel? NEWLINE ;

topLevel    : programDecl
            | unitsDecl
            | fixtureDecl
            | localDecl
            | pointDecl
            | palletDecl
            | vacuumDecl
            | varDecl
            | functionDecl
            ;

programDecl : PROGRAM ID ;
unitsDecl   : UNITS ID ;
fixtureDecl : FIXTURE ID ;
localDecl   : LOCAL ID '=' coords (IN ID)? ;
pointDecl   : TAUGHT? POINT ID '=' coords ((IN | ON) ID)? ;
palletDecl  : PALLET NUMBER ',' ID ',' ID ',' ID ',' NUMBER ',' NUMBER ;
vacuumDecl  : VACUUM NUMBER ;
varDecl     : (INTEGER | REAL) ID (',' ID)* ;
functionDecl: functionHead block FEND ;
// The opening line of each block is its own rule, for the same reason.
functionHead: FUNCTION ID ('(' ')')? NEWLINE ;

coords      : XY '(' signedNumber ',' signedNumber ',' signedNumber ',' signedNumber ')' ;
signedNumber: ('-' | '+')? NUMBER ;

block       : blockLine* ;
blockLine   : statement? NEWLINE ;

statement   : varDecl
            | assignment
            | motion
            | pickPlace
            | onOff
            | waitStmt
            | forStmt
            | ifStmt
            | callStmt
            | cycleStmt
            | scanStmt
            | exitStmt
            ;

assignment  : ID '=' expr ;
motion      : (JUMP | GO | MOVE) pointExpr (LIMZ expr)? ;
pickPlace   : (PICK | PLACE) pointExpr (VACUUM expr)? (LIMZ expr)? ;
onOff       : (ON | OFF) expr ;
// Wait Sw(n) = On|Off waits for an input; any other Wait expr waits that
// many seconds. Both are one rule (LL(1)); the visitor tells them apart.
waitStmt    : WAIT expr ;
forStmt     : forHead block NEXT ID? ;
forHead     : FOR ID '=' expr TO expr (STEP expr)? NEWLINE ;
ifStmt      : ifHead block elseIfPart* elsePart? ENDIF ;
ifHead      : IF expr THEN NEWLINE ;
elseIfPart  : elseIfHead block ;
elseIfHead  : ELSEIF expr THEN NEWLINE ;
elsePart    : elseHead block ;
elseHead    : ELSE NEWLINE ;
callStmt    : CALL ID ('(' ')')? ;
cycleStmt   : cycleHead block ENDCYCLE ;
cycleHead   : CYCLE ID NEWLINE ;
scanStmt    : SCAN ID ;
exitStmt    : EXIT FUNCTION ;

// ---------------------------------------------------------------- points
// P + X(d): the offset axis is an identifier (X, Y, Z or U) so that x, y, z
// and u stay usable as variable names; the parser checks it.
pointExpr   : pointAtom (('+' | '-') offset)* ;
pointAtom   : ID                                                # namedPoint
            | coords                                            # literalPoint
            | PALLET '(' expr ',' expr (',' expr)? ')'          # palletPoint
            ;
offset      : ID '(' expr ')' ;

// ---------------------------------------------------------------- expressions
expr        : '(' expr ')'                                      # parenExpr
            | op=('-' | '+' | NOT) expr                         # unaryExpr
            | expr op=('*' | '/' | MOD) expr                    # binaryExpr
            | expr op=('+' | '-') expr                          # binaryExpr
            | expr op=('=' | '<>' | '<' | '>' | '<=' | '>=') expr # binaryExpr
            | expr op=AND expr                                  # binaryExpr
            | expr op=(OR | XOR) expr                           # binaryExpr
            | SW '(' expr ')'                                   # switchExpr
            | (ON | OFF)                                        # onOffExpr
            | NUMBER                                            # numberExpr
            | ID                                                # variableExpr
            ;

// ---------------------------------------------------------------- tokens
PROGRAM  : P R O G R A M ;
UNITS    : U N I T S ;
FIXTURE  : F I X T U R E ;
LOCAL    : L O C A L ;
TAUGHT   : T A U G H T ;
POINT    : P O I N T ;
IN       : I N ;
ON       : O N ;
OFF      : O F F ;
XY       : X Y ;
PALLET   : P A L L E T ;
VACUUM   : V A C U U M ;
INTEGER  : I N T E G E R ;
REAL     : R E A L ;
FUNCTION : F U N C T I O N ;
FEND     : F E N D ;
JUMP     : J U M P ;
GO       : G O ;
MOVE     : M O V E ;
LIMZ     : L I M Z ;
PICK     : P I C K ;
PLACE    : P L A C E ;
WAIT     : W A I T ;
SW       : S W ;
FOR      : F O R ;
TO       : T O ;
STEP     : S T E P ;
NEXT     : N E X T ;
IF       : I F ;
THEN     : T H E N ;
ELSEIF   : E L S E I F ;
ELSE     : E L S E ;
ENDIF    : E N D I F ;
CALL     : C A L L ;
CYCLE    : C Y C L E ;
ENDCYCLE : E N D C Y C L E ;
SCAN     : S C A N ;
EXIT     : E X I T ;
AND      : A N D ;
OR       : O R ;
XOR      : X O R ;
NOT      : N O T ;
MOD      : M O D ;

// Punctuation has names so that frontend/parse.cpp can talk about it.
EQ       : '=' ;
NE       : '<>' ;
LE       : '<=' ;
GE       : '>=' ;
LT       : '<' ;
GT       : '>' ;
COMMA    : ',' ;
LPAREN   : '(' ;
RPAREN   : ')' ;
PLUS     : '+' ;
MINUS    : '-' ;
STAR     : '*' ;
SLASH    : '/' ;

NUMBER   : DIGIT+ ('.' DIGIT*)? EXPONENT? | '.' DIGIT+ EXPONENT? ;
ID       : [a-zA-Z_] [a-zA-Z_0-9]* ;
COMMENT  : '\'' ~[\r\n]* -> channel(HIDDEN) ;
NEWLINE  : '\r'? '\n' ;
WS       : [ \t]+ -> skip ;
// Anything else becomes a token the parser rejects with a clear message,
// instead of a lexer error about an unrecognised character.
BAD_CHAR : . ;

fragment DIGIT    : [0-9] ;
fragment EXPONENT : [eE] [+-]? DIGIT+ ;
fragment A : [aA] ; fragment B : [bB] ; fragment C : [cC] ; fragment D : [dD] ;
fragment E : [eE] ; fragment F : [fF] ; fragment G : [gG] ; fragment H : [hH] ;
fragment I : [iI] ; fragment J : [jJ] ; fragment K : [kK] ; fragment L : [lL] ;
fragment M : [mM] ; fragment N : [nN] ; fragment O : [oO] ; fragment P : [pP] ;
fragment Q : [qQ] ; fragment R : [rR] ; fragment S : [sS] ; fragment T : [tT] ;
fragment U : [uU] ; fragment V : [vV] ; fragment W : [wW] ; fragment X : [xX] ;
fragment Y : [yY] ; fragment Z : [zZ] ;
