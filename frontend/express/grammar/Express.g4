/*
 * Express.g4 -- ANTLR 4 grammar for the EXPRESS information modelling
 * language, ISO 10303-11:2004 (edition 2, including Technical
 * Corrigendum 1).  Part of stepnc (STEP-NC / ISO 14649 to CNC compiler).
 *
 * Written from the syntax productions of ISO 10303-11 Annex A
 * (productions 164-341 for the grammar, 123-149 for the lexical rules).
 * Parser rule names are the Annex A production names (snake_case), so a
 * construct can be looked up in the standard by name, e.g. entity_decl,
 * explicit_attr, supertype_expression, where_clause.
 *
 * Coverage
 *   - SCHEMA with optional schema version id (string literal); several
 *     schemas per file.
 *   - USE FROM / REFERENCE FROM with optional item lists and AS renames.
 *   - CONSTANT, TYPE (simple, aggregate, named, SELECT, ENUMERATION,
 *     incl. EXTENSIBLE [GENERIC_ENTITY] SELECT, SELECT BASED_ON .. WITH,
 *     EXTENSIBLE ENUMERATION, ENUMERATION BASED_ON .. WITH, type WHERE).
 *   - ENTITY: ABSTRACT, ABSTRACT SUPERTYPE [OF (...)], SUPERTYPE OF
 *     (...), ONEOF / AND / ANDOR supertype expressions, SUBTYPE OF,
 *     explicit attributes (incl. SELF\entity.attr [RENAMED id]),
 *     DERIVE, INVERSE, UNIQUE, WHERE.
 *   - SUBTYPE_CONSTRAINT (ABSTRACT SUPERTYPE, TOTAL_OVER, supertype
 *     expression), FUNCTION, PROCEDURE (VAR parameters), RULE .. FOR.
 *   - Generalized types: AGGREGATE[:label], GENERIC[:label],
 *     GENERIC_ENTITY[:label], general ARRAY/BAG/LIST/SET.
 *   - All statements (alias, assignment, case, compound, escape, if,
 *     null, procedure call, repeat with increment/WHILE/UNTIL control,
 *     return, skip) and the whole expression language with the
 *     standard's precedence levels.
 *   - Lexical: case-insensitive keywords and identifiers, binary
 *     literals (%0101), encoded strings ("0000004B"), simple strings with
 *     doubled quotes (may span lines, as edition 2 allows), integer and
 *     real literals, nested embedded remarks (* ... (* ... *) ... *) and
 *     tail remarks -- ... .  Remarks go to the HIDDEN channel (not
 *     skipped), so remark tags such as (*"schema.entity" ... *) or
 *     conformance-class tags can be recovered from the token stream.
 *
 * Deviations from the Annex A productions (and why)
 *   1. References.  Annex A distinguishes attribute_ref, constant_ref,
 *      entity_ref, function_ref, parameter_ref, population, type_ref,
 *      variable_ref, enumeration_ref ...  which are all just simple_id.
 *      Where the kind cannot be known from syntax alone the grammar uses
 *      one rule and the distinction is left to semantic analysis:
 *        - qualifiable_factor merges attribute_ref, constant_ref,
 *          general_ref, population, function_call and entity_constructor
 *          (an entity constructor "e(a, b)" has exactly the shape of a
 *          function call);
 *        - enumeration_reference "type.item" is parsed as a qualified
 *          primary (simple_id followed by an attribute qualifier);
 *        - named_types (entity_ref | type_ref) is a single simple_id;
 *          instantiable_type / concrete_types use named_types where the
 *          standard says type_ref | entity_ref;
 *        - resource_ref, rename_id and type_label are single simple_ids.
 *   2. actual_parameter_list may be empty "()" because entity
 *      constructors of entities without explicit attributes are written
 *      "e()" (entity_constructor allows that, function_call does not).
 *   3. simple_factor: the alternatives entity_constructor and
 *      enumeration_reference are folded into primary (see 1).
 *   4. Role names bound_1/bound_2, index_1/index_2, interval_low/item/
 *      high, width, precision_spec, repetition, increment, selector,
 *      aggregate_source, case_label ... are ANTLR labels on the
 *      underlying expression rules instead of separate rules.
 *   5. real literals: "1E5" (exponent without a decimal point) is
 *      accepted as a real literal; strictly EXPRESS requires "1.E5".
 *   6. Keyword tokens are prefixed K_ (K_ENTITY, K_TRUE, ...) and
 *      punctuation tokens are named, to avoid clashes with C++ keywords
 *      and common macros (TRUE, FALSE, IN, OPTIONAL, ...) in generated
 *      C++ code.
 *   No target-language actions or semantic predicates are used; the
 *   grammar generates Java and C++ with ANTLR 4.7.2 or later.
 *
 * Not checked (semantics): reference resolution, scoping and visibility,
 * type compatibility, reserved words of later editions used as
 * identifiers, conformance of edition-1 schemas (e.g. a domain rule
 * without a label is accepted as edition 2 allows).
 */
grammar Express;

// =====================================================================
// A.2 Grammar rules (top rule: syntax)
// =====================================================================

// 324
syntax
    : schema_decl+ EOF
    ;

// 296 / 298
schema_decl
    : K_SCHEMA schema_id schema_version_id? ';' schema_body K_END_SCHEMA ';'
    ;

schema_version_id
    : string_literal
    ;

// 295
schema_body
    : interface_specification* constant_decl? (declaration | rule_decl)*
    ;

// ---------------------------------------------------------------------
// Interface specifications (242, 281, 336, 259, 288, 289, 284)
// ---------------------------------------------------------------------

interface_specification
    : reference_clause
    | use_clause
    ;

reference_clause
    : K_REFERENCE K_FROM schema_ref ('(' resource_or_rename (',' resource_or_rename)* ')')? ';'
    ;

use_clause
    : K_USE K_FROM schema_ref ('(' named_type_or_rename (',' named_type_or_rename)* ')')? ';'
    ;

named_type_or_rename
    : named_types (K_AS rename_id)?
    ;

resource_or_rename
    : resource_ref (K_AS rename_id)?
    ;

// constant_ref | entity_ref | function_ref | procedure_ref | type_ref
resource_ref
    : simple_id
    ;

// constant_id | entity_id | function_id | procedure_id | type_id
rename_id
    : simple_id
    ;

// ---------------------------------------------------------------------
// Declarations (199)
// ---------------------------------------------------------------------

declaration
    : entity_decl
    | function_decl
    | procedure_decl
    | subtype_constraint_decl
    | type_decl
    ;

// 195 / 194
constant_decl
    : K_CONSTANT constant_body+ K_END_CONSTANT ';'
    ;

constant_body
    : constant_id ':' instantiable_type ':=' expression ';'
    ;

// ---------------------------------------------------------------------
// TYPE declarations (327, 332, 198, 302, 300, 301, 213, 209, 211)
// ---------------------------------------------------------------------

type_decl
    : K_TYPE type_id '=' underlying_type ';' where_clause? K_END_TYPE ';'
    ;

underlying_type
    : constructed_types
    | concrete_types
    ;

constructed_types
    : enumeration_type
    | select_type
    ;

select_type
    : (K_EXTENSIBLE K_GENERIC_ENTITY?)? K_SELECT (select_list | select_extension)?
    ;

select_list
    : '(' named_types (',' named_types)* ')'
    ;

select_extension
    : K_BASED_ON type_ref (K_WITH select_list)?
    ;

enumeration_type
    : K_EXTENSIBLE? K_ENUMERATION (K_OF enumeration_items | enumeration_extension)?
    ;

enumeration_items
    : '(' enumeration_id (',' enumeration_id)* ')'
    ;

enumeration_extension
    : K_BASED_ON type_ref (K_WITH enumeration_items)?
    ;

// ---------------------------------------------------------------------
// Data types (193, 240, 172, 175, 180, 250, 303, 185, 307, 266, 223..231)
// ---------------------------------------------------------------------

// concrete_types = aggregation_types | simple_types | type_ref
concrete_types
    : aggregation_types
    | simple_types
    | named_types
    ;

// instantiable_type = concrete_types | entity_ref
instantiable_type
    : concrete_types
    ;

aggregation_types
    : array_type
    | bag_type
    | list_type
    | set_type
    ;

array_type
    : K_ARRAY bound_spec K_OF K_OPTIONAL? K_UNIQUE? instantiable_type
    ;

bag_type
    : K_BAG bound_spec? K_OF instantiable_type
    ;

list_type
    : K_LIST bound_spec? K_OF K_UNIQUE? instantiable_type
    ;

set_type
    : K_SET bound_spec? K_OF instantiable_type
    ;

// bound_1 / bound_2 (183, 184)
bound_spec
    : '[' bound_1=numeric_expression ':' bound_2=numeric_expression ']'
    ;

simple_types
    : binary_type
    | boolean_type
    | integer_type
    | logical_type
    | number_type
    | real_type
    | string_type
    ;

binary_type
    : K_BINARY width_spec?
    ;

boolean_type
    : K_BOOLEAN
    ;

integer_type
    : K_INTEGER
    ;

logical_type
    : K_LOGICAL
    ;

number_type
    : K_NUMBER
    ;

// precision_spec = numeric_expression
real_type
    : K_REAL ('(' precision_spec=numeric_expression ')')?
    ;

string_type
    : K_STRING width_spec?
    ;

// width = numeric_expression
width_spec
    : '(' width=numeric_expression ')' K_FIXED?
    ;

// entity_ref | type_ref (not distinguishable by syntax)
named_types
    : simple_id
    ;

parameter_type
    : generalized_types
    | simple_types
    | named_types
    ;

generalized_types
    : aggregate_type
    | general_aggregation_types
    | generic_entity_type
    | generic_type
    ;

aggregate_type
    : K_AGGREGATE (':' type_label)? K_OF parameter_type
    ;

general_aggregation_types
    : general_array_type
    | general_bag_type
    | general_list_type
    | general_set_type
    ;

general_array_type
    : K_ARRAY bound_spec? K_OF K_OPTIONAL? K_UNIQUE? parameter_type
    ;

general_bag_type
    : K_BAG bound_spec? K_OF parameter_type
    ;

general_list_type
    : K_LIST bound_spec? K_OF K_UNIQUE? parameter_type
    ;

general_set_type
    : K_SET bound_spec? K_OF parameter_type
    ;

generic_entity_type
    : K_GENERIC_ENTITY (':' type_label)?
    ;

generic_type
    : K_GENERIC (':' type_label)?
    ;

// type_label_id | type_label_ref
type_label
    : simple_id
    ;

// ---------------------------------------------------------------------
// ENTITY declarations (206, 207, 312, 319, 322, 313, 318, 204, ...)
// ---------------------------------------------------------------------

entity_decl
    : entity_head entity_body K_END_ENTITY ';'
    ;

entity_head
    : K_ENTITY entity_id subsuper ';'
    ;

subsuper
    : supertype_constraint? subtype_declaration?
    ;

supertype_constraint
    : abstract_supertype_declaration
    | abstract_entity_declaration
    | supertype_rule
    ;

// ABSTRACT  (edition 2: abstract entity that is not necessarily a supertype)
abstract_entity_declaration
    : K_ABSTRACT
    ;

// ABSTRACT SUPERTYPE [ OF ( supertype_expression ) ]
abstract_supertype_declaration
    : K_ABSTRACT K_SUPERTYPE subtype_constraint?
    ;

// SUPERTYPE OF ( supertype_expression )
supertype_rule
    : K_SUPERTYPE subtype_constraint
    ;

subtype_constraint
    : K_OF '(' supertype_expression ')'
    ;

subtype_declaration
    : K_SUBTYPE K_OF '(' entity_ref (',' entity_ref)* ')'
    ;

// supertype_expression = supertype_factor { ANDOR supertype_factor }
supertype_expression
    : supertype_factor (K_ANDOR supertype_factor)*
    ;

// supertype_factor = supertype_term { AND supertype_term }
supertype_factor
    : supertype_term (K_AND supertype_term)*
    ;

supertype_term
    : entity_ref
    | one_of
    | '(' supertype_expression ')'
    ;

one_of
    : K_ONEOF '(' supertype_expression (',' supertype_expression)* ')'
    ;

entity_body
    : explicit_attr* derive_clause? inverse_clause? unique_clause? where_clause?
    ;

explicit_attr
    : attribute_decl (',' attribute_decl)* ':' K_OPTIONAL? parameter_type ';'
    ;

// attribute_decl = attribute_id | redeclared_attribute
attribute_decl
    : attribute_id
    | redeclared_attribute
    ;

redeclared_attribute
    : qualified_attribute (K_RENAMED attribute_id)?
    ;

// SELF \ entity_ref . attribute_ref
qualified_attribute
    : K_SELF group_qualifier attribute_qualifier
    ;

derive_clause
    : K_DERIVE derived_attr+
    ;

derived_attr
    : attribute_decl ':' parameter_type ':=' expression ';'
    ;

inverse_clause
    : K_INVERSE inverse_attr+
    ;

// attribute_decl ':' [ ( SET | BAG ) [ bound_spec ] OF ] entity_ref
//     FOR [ entity_ref '.' ] attribute_ref ';'
// referencing_entity: the entity whose attribute points back at us;
// declaring_entity: optional qualification naming the (super)type of
// referencing_entity that declares attribute_ref.
inverse_attr
    : attribute_decl ':' inverse_aggregate? referencing_entity=entity_ref
      K_FOR (declaring_entity=entity_ref '.')? attribute_ref ';'
    ;

inverse_aggregate
    : (K_SET | K_BAG) bound_spec? K_OF
    ;

unique_clause
    : K_UNIQUE (unique_rule ';')+
    ;

unique_rule
    : (rule_label_id ':')? referenced_attribute (',' referenced_attribute)*
    ;

referenced_attribute
    : attribute_ref
    | qualified_attribute
    ;

where_clause
    : K_WHERE (domain_rule ';')+
    ;

domain_rule
    : (rule_label_id ':')? expression
    ;

// ---------------------------------------------------------------------
// SUBTYPE_CONSTRAINT (315, 316, 314, 165, 326)
// ---------------------------------------------------------------------

subtype_constraint_decl
    : subtype_constraint_head subtype_constraint_body K_END_SUBTYPE_CONSTRAINT ';'
    ;

subtype_constraint_head
    : K_SUBTYPE_CONSTRAINT subtype_constraint_id K_FOR entity_ref ';'
    ;

subtype_constraint_body
    : abstract_supertype? total_over? (supertype_expression ';')?
    ;

abstract_supertype
    : K_ABSTRACT K_SUPERTYPE ';'
    ;

total_over
    : K_TOTAL_OVER '(' entity_ref (',' entity_ref)* ')' ';'
    ;

// ---------------------------------------------------------------------
// FUNCTION, PROCEDURE, RULE (220, 221, 218, 271, 272, 291, 292, 173, 252)
// ---------------------------------------------------------------------

function_decl
    : function_head algorithm_head stmt+ K_END_FUNCTION ';'
    ;

function_head
    : K_FUNCTION function_id
      ('(' formal_parameter (';' formal_parameter)* ')')?
      ':' parameter_type ';'
    ;

formal_parameter
    : parameter_id (',' parameter_id)* ':' parameter_type
    ;

procedure_decl
    : procedure_head algorithm_head stmt* K_END_PROCEDURE ';'
    ;

procedure_head
    : K_PROCEDURE procedure_id
      ('(' procedure_parameter (';' procedure_parameter)* ')')? ';'
    ;

// [ VAR ] formal_parameter
procedure_parameter
    : K_VAR? formal_parameter
    ;

rule_decl
    : rule_head algorithm_head stmt* where_clause K_END_RULE ';'
    ;

rule_head
    : K_RULE rule_id K_FOR '(' entity_ref (',' entity_ref)* ')' ';'
    ;

algorithm_head
    : declaration* constant_decl? local_decl?
    ;

local_decl
    : K_LOCAL local_variable+ K_END_LOCAL ';'
    ;

local_variable
    : variable_id (',' variable_id)* ':' parameter_type (':=' expression)? ';'
    ;

// ---------------------------------------------------------------------
// Statements (309 and following)
// ---------------------------------------------------------------------

stmt
    : alias_stmt
    | assignment_stmt
    | case_stmt
    | compound_stmt
    | escape_stmt
    | if_stmt
    | null_stmt
    | procedure_call_stmt
    | repeat_stmt
    | return_stmt
    | skip_stmt
    ;

alias_stmt
    : K_ALIAS variable_id K_FOR general_ref qualifier* ';' stmt+ K_END_ALIAS ';'
    ;

assignment_stmt
    : general_ref qualifier* ':=' expression ';'
    ;

// selector = expression
case_stmt
    : K_CASE selector=expression K_OF case_action* (K_OTHERWISE ':' otherwise=stmt)? K_END_CASE ';'
    ;

// case_label = expression
case_action
    : expression (',' expression)* ':' stmt
    ;

compound_stmt
    : K_BEGIN stmt+ K_END ';'
    ;

escape_stmt
    : K_ESCAPE ';'
    ;

if_stmt
    : K_IF logical_expression K_THEN then_stmts=stmt_list (K_ELSE else_stmts=stmt_list)? K_END_IF ';'
    ;

// stmt { stmt } (helper so THEN and ELSE branches are separate subtrees)
stmt_list
    : stmt+
    ;

null_stmt
    : ';'
    ;

procedure_call_stmt
    : (built_in_procedure | procedure_ref) actual_parameter_list? ';'
    ;

repeat_stmt
    : K_REPEAT repeat_control ';' stmt+ K_END_REPEAT ';'
    ;

repeat_control
    : increment_control? while_control? until_control?
    ;

// variable_id ':=' bound_1 TO bound_2 [ BY increment ]
increment_control
    : variable_id ':=' bound_1=numeric_expression K_TO bound_2=numeric_expression
      (K_BY increment=numeric_expression)?
    ;

while_control
    : K_WHILE logical_expression
    ;

until_control
    : K_UNTIL logical_expression
    ;

return_stmt
    : K_RETURN ('(' expression ')')? ';'
    ;

skip_stmt
    : K_SKIP ';'
    ;

// ---------------------------------------------------------------------
// Expressions (216, 305, 325, 217, 306, 269, 274, 276 ...)
// Precedence (lowest to highest): relational / IN / LIKE,
// + - OR XOR, * / DIV MOD AND ||, **, unary + - NOT, qualifiers.
// ---------------------------------------------------------------------

// expression = simple_expression [ rel_op_extended simple_expression ]
expression
    : simple_expression (rel_op_extended simple_expression)?
    ;

logical_expression
    : expression
    ;

numeric_expression
    : simple_expression
    ;

// simple_expression = term { add_like_op term }
simple_expression
    : term (add_like_op term)*
    ;

// term = factor { multiplication_like_op factor }
term
    : factor (multiplication_like_op factor)*
    ;

// factor = simple_factor [ '**' simple_factor ]
factor
    : simple_factor ('**' simple_factor)?
    ;

simple_factor
    : aggregate_initializer
    | interval
    | query_expression
    | unary_op? '(' expression ')'
    | unary_op? primary
    ;

// primary = literal | ( qualifiable_factor { qualifier } )
primary
    : literal
    | qualifiable_factor qualifier*
    ;

// attribute_ref | constant_factor | function_call | general_ref |
// population, plus entity_constructor and enumeration_ref (deviation 1).
qualifiable_factor
    : built_in_constant
    | built_in_function actual_parameter_list?
    | simple_id actual_parameter_list?
    ;

actual_parameter_list
    : '(' (parameter (',' parameter)*)? ')'
    ;

parameter
    : expression
    ;

qualifier
    : attribute_qualifier
    | group_qualifier
    | index_qualifier
    ;

attribute_qualifier
    : '.' attribute_ref
    ;

group_qualifier
    : '\\' entity_ref
    ;

// index_1 / index_2
index_qualifier
    : '[' index_1=numeric_expression (':' index_2=numeric_expression)? ']'
    ;

aggregate_initializer
    : '[' (element (',' element)*)? ']'
    ;

// repetition = numeric_expression
element
    : expression (':' repetition=numeric_expression)?
    ;

// '{' interval_low interval_op interval_item interval_op interval_high '}'
interval
    : '{' interval_low=simple_expression interval_op
          interval_item=simple_expression interval_op
          interval_high=simple_expression '}'
    ;

interval_op
    : '<'
    | '<='
    ;

// QUERY ( variable_id <* aggregate_source | logical_expression )
query_expression
    : K_QUERY '(' variable_id '<*' aggregate_source=simple_expression '|' logical_expression ')'
    ;

rel_op_extended
    : rel_op
    | K_IN
    | K_LIKE
    ;

rel_op
    : '<'
    | '>'
    | '<='
    | '>='
    | '<>'
    | '='
    | ':<>:'
    | ':=:'
    ;

add_like_op
    : '+'
    | '-'
    | K_OR
    | K_XOR
    ;

multiplication_like_op
    : '*'
    | '/'
    | K_DIV
    | K_MOD
    | K_AND
    | '||'
    ;

unary_op
    : '+'
    | '-'
    | K_NOT
    ;

built_in_constant
    : K_CONST_E
    | K_PI
    | K_SELF
    | '?'
    ;

built_in_function
    : K_ABS | K_ACOS | K_ASIN | K_ATAN | K_BLENGTH | K_COS | K_EXISTS
    | K_EXP | K_FORMAT | K_HIBOUND | K_HIINDEX | K_LENGTH | K_LOBOUND
    | K_LOINDEX | K_LOG | K_LOG2 | K_LOG10 | K_NVL | K_ODD | K_ROLESOF
    | K_SIN | K_SIZEOF | K_SQRT | K_TAN | K_TYPEOF | K_USEDIN | K_VALUE
    | K_VALUE_IN | K_VALUE_UNIQUE
    ;

built_in_procedure
    : K_INSERT
    | K_REMOVE
    ;

// literal = binary_literal | logical_literal | real_literal | string_literal
// (real_literal includes integer_literal)
literal
    : BINARY_LITERAL
    | INTEGER_LITERAL
    | REAL_LITERAL
    | logical_literal
    | string_literal
    ;

logical_literal
    : K_FALSE
    | K_TRUE
    | K_UNKNOWN
    ;

string_literal
    : SIMPLE_STRING_LITERAL
    | ENCODED_STRING_LITERAL
    ;

// ---------------------------------------------------------------------
// Identifiers (A.1.5: *_id are declarations, *_ref are references)
// ---------------------------------------------------------------------

simple_id            : SIMPLE_ID ;

attribute_id         : simple_id ;
constant_id          : simple_id ;
entity_id            : simple_id ;
enumeration_id       : simple_id ;
function_id          : simple_id ;
parameter_id         : simple_id ;
procedure_id         : simple_id ;
rule_id              : simple_id ;
rule_label_id        : simple_id ;
schema_id            : simple_id ;
subtype_constraint_id: simple_id ;
type_id              : simple_id ;
variable_id          : simple_id ;

attribute_ref        : simple_id ;
entity_ref           : simple_id ;
procedure_ref        : simple_id ;
schema_ref           : simple_id ;
type_ref             : simple_id ;
// parameter_ref | variable_ref
general_ref          : simple_id ;

// =====================================================================
// A.1 Lexical rules
// =====================================================================

// ---- Keywords (A.1.1), all case-insensitive -------------------------
K_ABS                    : A B S ;
K_ABSTRACT               : A B S T R A C T ;
K_ACOS                   : A C O S ;
K_AGGREGATE              : A G G R E G A T E ;
K_ALIAS                  : A L I A S ;
K_AND                    : A N D ;
K_ANDOR                  : A N D O R ;
K_ARRAY                  : A R R A Y ;
K_AS                     : A S ;
K_ASIN                   : A S I N ;
K_ATAN                   : A T A N ;
K_BAG                    : B A G ;
K_BASED_ON               : B A S E D '_' O N ;
K_BEGIN                  : B E G I N ;
K_BINARY                 : B I N A R Y ;
K_BLENGTH                : B L E N G T H ;
K_BOOLEAN                : B O O L E A N ;
K_BY                     : B Y ;
K_CASE                   : C A S E ;
K_CONSTANT               : C O N S T A N T ;
K_CONST_E                : C O N S T '_' E ;
K_COS                    : C O S ;
K_DERIVE                 : D E R I V E ;
K_DIV                    : D I V ;
K_ELSE                   : E L S E ;
K_END                    : E N D ;
K_END_ALIAS              : E N D '_' A L I A S ;
K_END_CASE               : E N D '_' C A S E ;
K_END_CONSTANT           : E N D '_' C O N S T A N T ;
K_END_ENTITY             : E N D '_' E N T I T Y ;
K_END_FUNCTION           : E N D '_' F U N C T I O N ;
K_END_IF                 : E N D '_' I F ;
K_END_LOCAL              : E N D '_' L O C A L ;
K_END_PROCEDURE          : E N D '_' P R O C E D U R E ;
K_END_REPEAT             : E N D '_' R E P E A T ;
K_END_RULE               : E N D '_' R U L E ;
K_END_SCHEMA             : E N D '_' S C H E M A ;
K_END_SUBTYPE_CONSTRAINT : E N D '_' S U B T Y P E '_' C O N S T R A I N T ;
K_END_TYPE               : E N D '_' T Y P E ;
K_ENTITY                 : E N T I T Y ;
K_ENUMERATION            : E N U M E R A T I O N ;
K_ESCAPE                 : E S C A P E ;
K_EXISTS                 : E X I S T S ;
K_EXP                    : E X P ;
K_EXTENSIBLE             : E X T E N S I B L E ;
K_FALSE                  : F A L S E ;
K_FIXED                  : F I X E D ;
K_FOR                    : F O R ;
K_FORMAT                 : F O R M A T ;
K_FROM                   : F R O M ;
K_FUNCTION               : F U N C T I O N ;
K_GENERIC                : G E N E R I C ;
K_GENERIC_ENTITY         : G E N E R I C '_' E N T I T Y ;
K_HIBOUND                : H I B O U N D ;
K_HIINDEX                : H I I N D E X ;
K_IF                     : I F ;
K_IN                     : I N ;
K_INSERT                 : I N S E R T ;
K_INTEGER                : I N T E G E R ;
K_INVERSE                : I N V E R S E ;
K_LENGTH                 : L E N G T H ;
K_LIKE                   : L I K E ;
K_LIST                   : L I S T ;
K_LOBOUND                : L O B O U N D ;
K_LOCAL                  : L O C A L ;
K_LOG                    : L O G ;
K_LOG10                  : L O G '10' ;
K_LOG2                   : L O G '2' ;
K_LOGICAL                : L O G I C A L ;
K_LOINDEX                : L O I N D E X ;
K_MOD                    : M O D ;
K_NOT                    : N O T ;
K_NUMBER                 : N U M B E R ;
K_NVL                    : N V L ;
K_ODD                    : O D D ;
K_OF                     : O F ;
K_ONEOF                  : O N E O F ;
K_OPTIONAL               : O P T I O N A L ;
K_OR                     : O R ;
K_OTHERWISE              : O T H E R W I S E ;
K_PI                     : P I ;
K_PROCEDURE              : P R O C E D U R E ;
K_QUERY                  : Q U E R Y ;
K_REAL                   : R E A L ;
K_REFERENCE              : R E F E R E N C E ;
K_REMOVE                 : R E M O V E ;
K_RENAMED                : R E N A M E D ;
K_REPEAT                 : R E P E A T ;
K_RETURN                 : R E T U R N ;
K_ROLESOF                : R O L E S O F ;
K_RULE                   : R U L E ;
K_SCHEMA                 : S C H E M A ;
K_SELECT                 : S E L E C T ;
K_SELF                   : S E L F ;
K_SET                    : S E T ;
K_SIN                    : S I N ;
K_SIZEOF                 : S I Z E O F ;
K_SKIP                   : S K I P ;
K_SQRT                   : S Q R T ;
K_STRING                 : S T R I N G ;
K_SUBTYPE                : S U B T Y P E ;
K_SUBTYPE_CONSTRAINT     : S U B T Y P E '_' C O N S T R A I N T ;
K_SUPERTYPE              : S U P E R T Y P E ;
K_TAN                    : T A N ;
K_THEN                   : T H E N ;
K_TO                     : T O ;
K_TOTAL_OVER             : T O T A L '_' O V E R ;
K_TRUE                   : T R U E ;
K_TYPE                   : T Y P E ;
K_TYPEOF                 : T Y P E O F ;
K_UNIQUE                 : U N I Q U E ;
K_UNKNOWN                : U N K N O W N ;
K_UNTIL                  : U N T I L ;
K_USE                    : U S E ;
K_USEDIN                 : U S E D I N ;
K_VALUE                  : V A L U E ;
K_VALUE_IN               : V A L U E '_' I N ;
K_VALUE_UNIQUE           : V A L U E '_' U N I Q U E ;
K_VAR                    : V A R ;
K_WHERE                  : W H E R E ;
K_WHILE                  : W H I L E ;
K_WITH                   : W I T H ;
K_XOR                    : X O R ;

// ---- Symbols (A.1.3 special characters) ------------------------------
// Longest match: ':=:' / ':<>:' before ':=' / ':', '<*' / '<=' / '<>' before '<'.
INST_EQ      : ':=:' ;
INST_NEQ     : ':<>:' ;
ASSIGN       : ':=' ;
COLON        : ':' ;
SEMI         : ';' ;
COMMA        : ',' ;
DOT          : '.' ;
BACKSLASH    : '\\' ;
LPAREN       : '(' ;
RPAREN       : ')' ;
LBRACKET     : '[' ;
RBRACKET     : ']' ;
LBRACE       : '{' ;
RBRACE       : '}' ;
QUERY_OP     : '<*' ;
LE           : '<=' ;
NEQ          : '<>' ;
LT           : '<' ;
GE           : '>=' ;
GT           : '>' ;
EQ           : '=' ;
POWER        : '**' ;
STAR         : '*' ;
SLASH        : '/' ;
PLUS         : '+' ;
MINUS        : '-' ;
CONCAT       : '||' ;
BAR          : '|' ;
QUESTION     : '?' ;

// ---- Remarks (7.1.6): kept on the HIDDEN channel ---------------------
// Embedded remarks nest: (* outer (* inner *) still outer *)
EMBEDDED_REMARK
    : '(*' (EMBEDDED_REMARK | .)*? '*)' -> channel(HIDDEN)
    ;

TAIL_REMARK
    : '--' ~[\r\n]* -> channel(HIDDEN)
    ;

// ---- Literals (A.1.2) ------------------------------------------------
// binary_literal = '%' bit { bit }
BINARY_LITERAL
    : '%' [01]+
    ;

// real_literal = digits '.' [ digits ] [ 'e' [ sign ] digits ]
// (also "digits e [sign] digits", deviation 5)
REAL_LITERAL
    : DIGITS '.' DIGITS? EXPONENT?
    | DIGITS EXPONENT
    ;

INTEGER_LITERAL
    : DIGITS
    ;

// simple_string_literal = \q { ( \q \q ) | not_quote | \s | \x9 | \xA | \xD } \q
SIMPLE_STRING_LITERAL
    : '\'' ( '\'\'' | ~'\'' )* '\''
    ;

// encoded_string_literal = '"' encoded_character { encoded_character } '"'
// encoded_character = octet octet octet octet
ENCODED_STRING_LITERAL
    : '"' (HEX HEX HEX HEX HEX HEX HEX HEX)+ '"'
    ;

// simple_id = letter { letter | digit | '_' }
SIMPLE_ID
    : LETTER (LETTER | DIGIT | '_')*
    ;

WS
    : [ \t\r\n\f]+ -> skip
    ;

// Anything else is reported by the lexer as a token recognition error.

// ---- Fragments --------------------------------------------------------
fragment DIGITS   : DIGIT+ ;
fragment DIGIT    : [0-9] ;
fragment EXPONENT : E [+-]? DIGITS ;
fragment HEX      : [0-9a-fA-F] ;
fragment LETTER   : [a-zA-Z] ;

fragment A : [aA] ;
fragment B : [bB] ;
fragment C : [cC] ;
fragment D : [dD] ;
fragment E : [eE] ;
fragment F : [fF] ;
fragment G : [gG] ;
fragment H : [hH] ;
fragment I : [iI] ;
fragment J : [jJ] ;
fragment K : [kK] ;
fragment L : [lL] ;
fragment M : [mM] ;
fragment N : [nN] ;
fragment O : [oO] ;
fragment P : [pP] ;
fragment Q : [qQ] ;
fragment R : [rR] ;
fragment S : [sS] ;
fragment T : [tT] ;
fragment U : [uU] ;
fragment V : [vV] ;
fragment W : [wW] ;
fragment X : [xX] ;
fragment Y : [yY] ;
fragment Z : [zZ] ;
