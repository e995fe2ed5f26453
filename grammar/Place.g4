// Place.g4 - the .place robot language (docs/language.md is the reference).
// SPEL+ flavour: case-insensitive keywords, ' comments, one statement per line.
// Generated into the build tree at build time; frontend/parse.cpp is the only
// code that sees the generated parser (frontend/place_lexer.cpp takes the
// token types from the generated lexer, which the differential test of the
// hand-written lexer runs as its reference).
grammar Place;

// ---------------------------------------------------------------- lines
// frontend/parse.cpp parses one line at a time: it calls the rule for the
// line's kind (known from its first word), builds the line's IR from the
// labelled elements and frees the line's parse tree. The blocks (Function
// ... Fend, For ... Next, If ... EndIf, Cycle ... EndCycle) are put
// together by parse.cpp from the nesting its pre-scan has checked and
// repaired, so a mistake anywhere in a line is caught inside that line and
// never abandons the block around it. Every line rule ends in the line's
// NEWLINE: parse.cpp gives each line one (also a last line that lacks it).
// parse.cpp reads the elements it needs through their labels only: it does
// not have ANTLR build the children lists of the parse tree. The kinds of
// declaration and statement are alternatives of their line's rule, not a
// rule of their own: each rule level costs the parser about as much as a
// token does.
declarationLine : ( programAlt=programDecl
                  | unitsAlt=unitsDecl
                  | fixtureAlt=fixtureDecl
                  | localAlt=localDecl
                  | pointAlt=pointDecl
                  | palletAlt=palletDecl
                  | vacuumAlt=vacuumDecl
                  | varDeclAlt=varDecl
                  ) NEWLINE ;
statementLine   : ( varDeclAlt=varDecl
                  | assignmentAlt=assignment
                  | motionAlt=motion
                  | pickPlaceAlt=pickPlace
                  | onOffAlt=onOff
                  | waitAlt=waitStmt
                  | callAlt=callStmt
                  | scanAlt=scanStmt
                  | exitAlt=exitStmt
                  ) NEWLINE ;
// The lines that open and close blocks.
functionHead: FUNCTION name=ID ('(' ')')? NEWLINE ;
forHead     : FOR var=ID '=' from=expr TO to=expr (STEP step=expr)? NEWLINE ;
ifHead      : IF condition=expr THEN NEWLINE ;
elseIfHead  : ELSEIF condition=expr THEN NEWLINE ;
elseHead    : ELSE NEWLINE ;
cycleHead   : CYCLE fixture=ID NEWLINE ;
fendLine    : FEND NEWLINE ;
nextLine    : NEXT var=ID? NEWLINE ;
endIfLine   : ENDIF NEWLINE ;
endCycleLine: ENDCYCLE NEWLINE ;

// ---------------------------------------------------------------- declarations
programDecl : PROGRAM name=ID ;
unitsDecl   : UNITS unit=ID ;
fixtureDecl : FIXTURE name=ID ;
localDecl   : LOCAL name=ID '=' origin=coords (IN frame=ID)? ;
pointDecl   : taught=TAUGHT? POINT name=ID '=' position=coords (frameKeyword=(IN | ON) frame=ID)? ;
palletDecl  : PALLET number=NUMBER ',' corner1=ID ',' corner2=ID ',' corner3=ID ',' columns=NUMBER ',' rows=NUMBER ;
vacuumDecl  : VACUUM output=NUMBER ;
varDecl     : type=(INTEGER | REAL) names+=ID (',' names+=ID)* ;

// Four numbers, each with its sign (written out: a rule level per number
// would cost the parser as much as the whole rest of a point's line).
coords      : XY '(' xSign=('-' | '+')? x=NUMBER ',' ySign=('-' | '+')? y=NUMBER ','
                     zSign=('-' | '+')? z=NUMBER ',' uSign=('-' | '+')? u=NUMBER ')' ;

// ---------------------------------------------------------------- statements
assignment  : name=ID '=' value=expr ;
motion      : kind=(JUMP | GO | MOVE) target=pointExpr (limzKeyword=LIMZ limz=expr)? ;
pickPlace   : kind=(PICK | PLACE) target=pointExpr (VACUUM vacuum=expr)? (LIMZ limz=expr)? ;
onOff       : state=(ON | OFF) bit=expr ;
// Wait Sw(n) = On|Off waits for an input; any other Wait expr waits that
// many seconds. Both are one rule (LL(1)); parse.cpp tells them apart.
waitStmt    : WAIT value=expr ;
callStmt    : CALL name=ID ('(' ')')? ;
scanStmt    : SCAN fixture=ID ;
exitStmt    : EXIT FUNCTION ;

// ---------------------------------------------------------------- points
// P + X(d): the offset axis is an identifier (X, Y, Z or U) so that x, y, z
// and u stay usable as variable names; the parser checks it.
// The point itself is an alternative of pointExpr, not a rule of its own
// (a rule level costs the parser about as much as a token).
pointExpr   : (name=ID | position=coords | pallet=palletPoint) (signs+=('+' | '-') offsets+=offset)* ;
palletPoint : PALLET '(' number=expr ',' i=expr (',' j=expr)? ')' ;
offset      : axis=ID '(' amount=expr ')' ;

// ---------------------------------------------------------------- expressions
expr        : '(' inner=expr ')'                                          # parenExpr
            | op=('-' | '+' | NOT) operand=expr                           # unaryExpr
            | lhs=expr op=('*' | '/' | MOD) rhs=expr                      # binaryExpr
            | lhs=expr op=('+' | '-') rhs=expr                            # binaryExpr
            | lhs=expr op=('=' | '<>' | '<' | '>' | '<=' | '>=') rhs=expr # binaryExpr
            | lhs=expr op=AND rhs=expr                                    # binaryExpr
            | lhs=expr op=(OR | XOR) rhs=expr                             # binaryExpr
            | SW '(' bit=expr ')'                                         # switchExpr
            | (ON | OFF)                                                  # onOffExpr
            | NUMBER                                                      # numberExpr
            | ID                                                          # variableExpr
            ;
// (The one-token alternatives have no label: the token is the context's
// start, and a label in a left-recursive rule costs the parser a type check.)

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
