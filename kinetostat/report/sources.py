"""The works the bundled models and the reports cite, each by the short citation the texts write
("Kiriienko 2019"), with its full reference: the bibliography of a report and of the index.

May use: the standard library.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable


@dataclass(frozen=True)
class Work:
    """A cited work: `key` is the short citation written in a text, `reference` the full one
    (authors, original title with an English translation, publisher or place, year)."""
    key: str
    reference: str


WORKS: tuple[Work, ...] = (
    Work("Kiriienko 2019",
         "Кірієнко О. А. (укладач). Теорія механізмів і машин. Розділ «Кінетостатичний аналіз механізмів»: "
         "навчальний посібник з кредитного модуля [Kiriienko O. A. (comp.) Theory of machines and mechanisms. "
         "Section \"Kinetostatic analysis of mechanisms\": a textbook]. Київ: НТУУ «КПІ ім. Ігоря Сікорського», "
         "2019. 64 с."),
    Work("Logvinenko, Nadtoka 2021",
         "Логвіненко О. А., Надтока О. В. Методичні вказівки до виконання розрахунково-графічних робіт з "
         "дисципліни «Технічна механіка» [Logvinenko O. A., Nadtoka O. V. Guidelines for the design and "
         "graphics assignments in Technical Mechanics]. Харків: Український державний університет "
         "залізничного транспорту, 2021."),
    Work("Potapov 2024",
         "Потапов В. А. Исследование сил взаимодействия звеньев приводного механизма цепного агрегата "
         "[Potapov V. A. Investigation of the interaction forces of the links of a chain unit's drive "
         "mechanism]. Journal article (УДК 531.8), Барановичский государственный университет; received by the "
         "editors 19.09.2024. The pages available do not name the journal; the author's earlier paper on this "
         "mechanism appeared in «Вестник БарГУ. Серия „Технические науки“» (2022, № 2)."),
    Work("Artobolevsky 1988",
         "Артоболевский И. И. Теория механизмов и машин: учебник для втузов. 4-е изд. [Artobolevsky I. I. "
         "Theory of mechanisms and machines: a textbook]. Москва: Наука, 1988. 640 с. (the class-III group "
         "III3: its structure, Assur's special points, its positions, plans and force analysis)."),
    Work("TMM course text on friction",
         "Anonymous course page (Russian), undated: a text on the theory of machines and mechanisms, pp. 81–82, "
         "the order of the force analysis with friction in the pairs («Отделяют от механизма структурные "
         "группы...»). The pages available name no author, title, publisher or year."),
)


def cited(texts: Iterable[str]) -> list[Work]:
    """The works whose short citation occurs in any of `texts`, in the order of WORKS."""
    joined = "\n".join(texts)
    return [w for w in WORKS if w.key in joined]
